#!/usr/bin/env bash
# Fetches Intel Open Image Denoise's prebuilt Linux libraries (the `pyoidn` wheel on PyPI, Apache-2.0)
# into third_party/oidn/lib, where `cohort --denoise oidn` and the denoiser tests look for them.
# Only the libraries Cohort loads are kept: the API library, its core, the CPU and CUDA devices and TBB.
# Usage: tools/fetch_oidn.sh [destination]     (default: third_party/oidn beside this script's repo)
# Idempotent; exits 0 with a message (and no library) when PyPI cannot be reached: the denoiser is optional.
set -euo pipefail
cd "$(dirname "$0")/.."
version="2.5.1.0"
dest="${1:-third_party/oidn}"
stamp="$dest/lib/.pyoidn-$version"
if [ -e "$stamp" ]; then
  echo "fetch_oidn.sh: Open Image Denoise $version already in $dest/lib."
  exit 0
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "fetch_oidn.sh: downloading pyoidn==$version (about 90 MB; about 60 MB is kept) from PyPI..."
if ! python3 -m pip download --quiet --no-deps --only-binary=:all: --platform manylinux2014_x86_64 \
       --python-version 3.11 "pyoidn==$version" -d "$work" 2>"$work/pip.log"; then
  echo "fetch_oidn.sh: could not download pyoidn (the OIDN denoiser stays unavailable):" >&2
  tail -n 3 "$work/pip.log" >&2
  exit 0
fi

wheel="$(ls "$work"/pyoidn-*.whl)"
mkdir -p "$dest/lib"
python3 - "$wheel" "$dest/lib" <<'EOF'
import os, sys, zipfile
wheel, out = sys.argv[1], sys.argv[2]
wanted = {"libOpenImageDenoise.so.2", "libOpenImageDenoise_core.so.2.5.1",
          "libOpenImageDenoise_device_cpu.so.2.5.1", "libOpenImageDenoise_device_cuda.so.2.5.1", "libtbb.so.12"}
with zipfile.ZipFile(wheel) as z:
    for info in z.infolist():
        name = os.path.basename(info.filename)
        if "/lib/" in info.filename and name in wanted:
            with z.open(info) as src, open(os.path.join(out, name), "wb") as dst:
                dst.write(src.read())
            print("  " + name)
EOF
touch "$stamp"
echo "fetch_oidn.sh: Open Image Denoise $version is in $dest/lib."

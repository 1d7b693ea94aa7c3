#!/usr/bin/env bash
# Creates .venv-quality (not committed) with NVIDIA's FLIP (flip-evaluator), numpy and matplotlib from
# PyPI, for bench/quality/bench_quality.py. Idempotent.
set -euo pipefail
cd "$(dirname "$0")/../.."
[ -x .venv-quality/bin/python ] || python3 -m venv .venv-quality
.venv-quality/bin/python -m pip install --quiet --upgrade pip
.venv-quality/bin/python -m pip install --quiet -r bench/quality/requirements.txt
echo "bench quality environment ready: .venv-quality/bin/python bench/quality/bench_quality.py --help"

#!/usr/bin/env python3
"""tools/kernel_resources.py on a two-kernel source compiled as the build compiles (SASS for sm_90 plus PTX):
each kernel gets one row, a kernel with a local array indexed at run time has a stack frame and the other
none, the build's object is left alone, and a folder without compile commands is a clear error.

    kernel_resources_test.py TOOLS/kernel_resources.py NVCC
"""
import json
import os
import subprocess
import sys
import tempfile

SOURCE = r"""
__global__ void plain_kernel(float* out) { out[threadIdx.x] = 2.0f * threadIdx.x; }
__global__ void local_array_kernel(float* out, int pick) {
  float table[64];
  for (int i = 0; i < 64; ++i) table[(i * pick) & 63] = out[i];
  out[threadIdx.x] = table[(pick + threadIdx.x) & 63];
}
"""


def main():
    tool, nvcc = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as folder:
        with open(os.path.join(folder, "two_kernels.cu"), "w") as f:
            f.write(SOURCE)
        command = (f"{nvcc} -O3 --generate-code=arch=compute_90,code=[sm_90] "
                   f"--generate-code=arch=compute_90,code=[compute_90] -x cu -c {folder}/two_kernels.cu "
                   f"-o {folder}/two_kernels.o")
        with open(os.path.join(folder, "compile_commands.json"), "w") as f:
            json.dump([{"directory": folder, "command": command, "file": f"{folder}/two_kernels.cu"}], f)
        out = subprocess.run([sys.executable, tool, folder, "two_kernels.cu"], capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        rows = {}
        for line in out.stdout.splitlines():
            fields = line.split()
            if fields and fields[0] in ("plain_kernel", "local_array_kernel"):
                rows[fields[0]] = [int(v) for v in fields[1:]]
        assert set(rows) == {"plain_kernel", "local_array_kernel"}, out.stdout
        assert rows["plain_kernel"][0] > 0 and rows["plain_kernel"][1] == 0, rows
        assert rows["local_array_kernel"][1] >= 64 * 4, rows  # the table lives in the stack frame
        assert out.stdout.count("plain_kernel") == 1, out.stdout
        assert not os.path.exists(os.path.join(folder, "two_kernels.o")), "the tool wrote the build's object"

        missing = subprocess.run([sys.executable, tool, os.path.join(folder, "nowhere")], capture_output=True,
                                 text=True)
        assert missing.returncode != 0 and "compile_commands.json" in missing.stderr, missing.stderr
    print("kernel_resources: rows, stack frames and errors as expected")


if __name__ == "__main__":
    main()

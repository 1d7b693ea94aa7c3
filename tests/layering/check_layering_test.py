#!/usr/bin/env python3
"""tools/check_layering.py must reject an upward include and an upward link, and accept a clean tree."""
import pathlib
import subprocess
import sys
import tempfile

CHECKER = pathlib.Path(sys.argv[1])


def run(root):
    return subprocess.run([sys.executable, str(CHECKER), str(root)], capture_output=True, text=True)


def write(root, rel, text):
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


with tempfile.TemporaryDirectory() as tmp:
    root = pathlib.Path(tmp)
    write(root, "kernel/include/cohort/kernel/layout.h", "#pragma once\n")
    write(root, "commit/CMakeLists.txt", "cohort_module_link(cohort_commit PUBLIC cohort_kernel)\n")
    write(root, "commit/src/a.cpp", '#include "cohort/kernel/layout.h"\n')
    write(root, "core/src/b.cpp", '#include "cohort/commit/tracer_scene.h"\n#include "cohort/scene/scene.h"\n')
    clean = run(root)
    assert clean.returncode == 0, f"clean tree rejected:\n{clean.stdout}{clean.stderr}"

    write(root, "kernel/include/cohort/kernel/bad.h", '/* x */\n#include "cohort/core/renderer.h"\n')
    write(root, "commit/CMakeLists.txt", "cohort_module_link(cohort_commit PUBLIC cohort_kernel cohort_scene)\n")
    write(root, "tracers/embree_cpu/src/t.cpp", '#include "cohort/tracers/cuda_tracer.h"\n')
    bad = run(root)
    assert bad.returncode == 1, f"violations accepted:\n{bad.stdout}"
    lines = bad.stdout.splitlines()
    expected = ["kernel/include/cohort/kernel/bad.h:2: module kernel includes cohort/core/renderer.h",
                "commit/CMakeLists.txt:1: module commit links cohort_scene",
                "tracers/embree_cpu/src/t.cpp:1: module tracers/embree includes cohort/tracers/cuda_tracer.h"]
    for e in expected:
        assert any(line.startswith(e) for line in lines), f"missing '{e}' in:\n{bad.stdout}"
    assert len(lines) == len(expected), f"unexpected extra reports:\n{bad.stdout}"
print("check_layering_test: ok")

#!/usr/bin/env python3
"""Checks that Cohort's modules depend on each other only in the stated direction.

Each module may include headers of, and link against, only the modules listed for it below (and
itself). Both the `#include "cohort/<module>/..."` lines of its sources and the cohort_* targets named
in its CMakeLists.txt are checked. Exit status 1 and one line per violation (file:line: what) when the
tree breaks the rule; 0 when it holds.

    tools/check_layering.py [source-root]
"""
import pathlib
import re
import sys

# module -> (folder, CMake target, modules it may depend on). The README's dependency line says the same.
MODULES = {
    "kernel":         ("kernel",             "cohort_kernel",         []),
    "scene":          ("scene",              "cohort_scene",          []),
    "balance":        ("balance",            "cohort_balance",        []),
    "commit":         ("commit",             "cohort_commit",         ["kernel"]),
    "core":           ("core",               "cohort_core",           ["kernel", "scene", "balance", "commit"]),
    "tracers/common": ("tracers/common",     "cohort_tracer_common",  ["kernel", "commit", "core"]),
    "tracers/embree": ("tracers/embree_cpu", "cohort_tracer_embree",  ["kernel", "commit", "core", "tracers/common"]),
    "tracers/opencl": ("tracers/opencl",     "cohort_tracer_opencl",  ["kernel", "commit", "core", "tracers/common"]),
    "tracers/cuda":   ("tracers/cuda",       "cohort_tracer_cuda",    ["kernel", "commit", "core", "tracers/common"]),
    "tracers/mpi":    ("tracers/mpi",        "cohort_tracer_mpi",     ["kernel", "commit", "core", "tracers/common", "balance"]),
    "tracers/registry": ("tracers/registry", "cohort_tracer_registry", ["kernel", "commit", "core", "tracers/common",
                                                                        "tracers/embree", "tracers/opencl", "tracers/cuda",
                                                                        "tracers/mpi"]),
}

# Public header folders: cohort/<name>/ -> module. Tracer headers all live under cohort/tracers/.
HEADER_OWNER = {"kernel": "kernel", "scene": "scene", "balance": "balance", "commit": "commit", "core": "core"}
TRACER_HEADERS = {  # header file stem prefix under cohort/tracers/ -> module
    "embree": "tracers/embree", "opencl": "tracers/opencl", "cuda": "tracers/cuda", "mpi": "tracers/mpi", "tracer_registry": "tracers/registry",
}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]cohort/([a-z_]+)/([^">]+)[">]')
TARGET = re.compile(r"\b(cohort_(?:kernel|scene|balance|commit|core|tracer_[a-z_]+))\b")
SOURCE_SUFFIXES = {".h", ".hpp", ".cpp", ".cu", ".cuh", ".cl"}


def owner_of_header(folder, path):
    if folder == "tracers":
        for prefix, module in TRACER_HEADERS.items():
            if path.startswith(prefix):
                return module
        return "tracers/common"
    return HEADER_OWNER.get(folder)


def module_of_target(name):
    for module, (_, target, _) in MODULES.items():
        if target == name:
            return module
    return None


def check(root):
    problems = []
    for module, (folder, target, allowed) in MODULES.items():
        allowed = set(allowed) | {module}
        base = root / folder
        if not base.is_dir():
            continue
        for path in sorted(base.rglob("*")):
            if path.suffix not in SOURCE_SUFFIXES or not path.is_file():
                continue
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                used = owner_of_header(match.group(1), match.group(2))
                if used and used not in allowed:
                    problems.append(f"{path.relative_to(root)}:{number}: module {module} includes "
                                    f"cohort/{match.group(1)}/{match.group(2)} of module {used}")
        cmake = base / "CMakeLists.txt"
        if cmake.is_file():
            for number, line in enumerate(cmake.read_text().splitlines(), 1):
                if "link" not in line:
                    continue
                for name in TARGET.findall(line):
                    used = module_of_target(name)
                    if used and used not in allowed:
                        problems.append(f"{cmake.relative_to(root)}:{number}: module {module} links {name} "
                                        f"of module {used}")
    return problems


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print(f"check_layering: {len(problems)} dependencies against the stated direction", file=sys.stderr)
        return 1
    print(f"check_layering: {len(MODULES)} modules depend only downward")
    return 0


if __name__ == "__main__":
    sys.exit(main())

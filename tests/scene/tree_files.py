"""A folder's files for the generated-map tests (testmap_generator_test.py, largemap_test.py)."""
import os


def read_tree(root):
    """Every file below root: its path relative to root (with '/') -> its bytes."""
    files = {}
    for folder, _, names in os.walk(root):
        for name in names:
            path = os.path.join(folder, name)
            with open(path, "rb") as handle:
                files[os.path.relpath(path, root).replace(os.sep, "/")] = handle.read()
    return files

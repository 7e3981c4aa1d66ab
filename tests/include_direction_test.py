"""Every include runs one way: down the layers of the code, never up, so no two folders
include each other (docs/architecture.md draws them).

Each folder has a layer; a file may include files of its own folder and of folders in
lower layers only. An include that runs back up (a store/ file including render/, core/
including problems/) fails the test, naming the file, the line and both layers; so does a
folder the list below does not know, or an include of a project file that does not exist.

usage: include_direction_test.py SOURCE_DIR
"""
import os
import re
import sys

# Low to high. Folders in one layer must not include each other either.
LAYERS = [
    ["include"],  # the plugin ABI, a C header that includes nothing of ours (docs/plugins.md)
    ["references"],
    ["core"],
    ["problems", "integrators"],
    ["peers"],
    ["registry"],
    ["study"],  # the study as data: what the run fills and the reader reads
    ["run"],
    ["judge"],
    ["store"],
    ["render"],
    ["parts"],
    ["cli"],
    ["bench"],
]
RANK = {folder: rank for rank, folders in enumerate(LAYERS) for folder in folders}
# Headers CMake generates into the build tree, named without a folder.
GENERATED = {"all_problems.hpp", "problem_entries.hpp", "problem_tags_check.hpp", "build_info.hpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def folder_of(path):
    return path.split("/", 1)[0]


def main():
    root = sys.argv[1]
    failures, files = [], 0
    for folder in sorted(os.listdir(root)):
        top = os.path.join(root, folder)
        if not os.path.isdir(top) or folder.startswith((".", "build")) or folder in ("tests", "docs", "scripts", "results", "examples"):
            continue
        for dirpath, _, names in os.walk(top):
            for name in sorted(names):
                if not name.endswith((".hpp", ".cpp", ".h", ".in")):
                    continue
                path = os.path.relpath(os.path.join(dirpath, name), root)
                files += 1
                if folder not in RANK:
                    failures.append(f"{path}: folder {folder}/ has no layer in tests/include_direction_test.py")
                    continue
                with open(os.path.join(root, path), encoding="utf-8") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = m.group(1)
                        if target in GENERATED or "@" in target:
                            continue
                        if "/" not in target:
                            failures.append(f"{path}:{number}: #include \"{target}\" names no folder")
                            continue
                        if not os.path.exists(os.path.join(root, target)):
                            failures.append(f"{path}:{number}: #include \"{target}\": no such file")
                            continue
                        to = folder_of(target)
                        if to == folder:
                            continue
                        if to not in RANK:
                            failures.append(f"{path}:{number}: includes {target}, whose folder has no layer")
                        elif RANK[to] >= RANK[folder]:
                            failures.append(f"{path}:{number}: includes {target}: {folder}/ (layer {RANK[folder]}) "
                                            f"must not include {to}/ (layer {RANK[to]}), which is "
                                            f"{'the same layer' if RANK[to] == RANK[folder] else 'above it'}")
    for f in failures:
        print("FAIL:", f)
    print(f"{files} files, {len(failures)} includes against the layers")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

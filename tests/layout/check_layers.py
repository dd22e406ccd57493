#!/usr/bin/env python3
"""The layout's own test (docs/architecture.md "Layers and targets").

Checks, from the source tree alone:
  1. every library target (pbvbus_layer(NAME ... DEPS ...) in a CMakeLists.txt, and the command
     line's target_link_libraries) has the dependencies that docs/architecture.md's picture
     ("```layers" block: `target (folder): dep dep ...`) says, no more and no fewer;
  2. no target depends on a target of its own floor or a higher one (floors: the picture's order,
     bottom first), so dependencies point downward only;
  3. every `#include "pbvbus/<name>/..."` in a target's folder names the target itself or one it
     reaches through its dependencies (a header-only upward include links, so CMake alone would
     not catch it); a file in a nested target's folder (gateways/iso_on_tcp inside gateways/)
     is checked as that target's only: the longest folder that contains it wins;
  4. the tests mirror the tree: every tests/<folder>/ with *_test.cpp files belongs to a target of
     the same folder (or is one of the cross-cutting suites: integration, hotpath, support, fuzz, layout).
Exit status 0 when all hold; otherwise each problem on its own line and exit status 1.
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
CROSS_CUTTING = {"integration", "support", "fuzz", "layout", "data", "hotpath"}


def cmake_targets():
    """{name: (folder, [deps])} for the project's libraries, from the CMakeLists files."""
    targets = {}
    for cm in sorted(ROOT.glob("**/CMakeLists.txt")):
        rel = cm.parent.relative_to(ROOT).as_posix()
        if rel.startswith(("build", "tests", "bench")) or "/build" in rel:
            continue
        text = re.sub(r"#.*", "", cm.read_text())
        for m in re.finditer(r"pbvbus_layer\(\s*NAME\s+(\w+)((?:\s+DEPS)?[^)]*)\)", text):
            deps = re.findall(r"pbvbus::(\w+)", m.group(2))
            targets[m.group(1)] = (rel, deps)
        m = re.search(r"add_library\(pbvbus_(\w+) STATIC", text)
        if m and m.group(1) not in targets:
            name = m.group(1)
            link = re.search(r"target_link_libraries\(pbvbus_%s PUBLIC([^)]*)\)" % name, text)
            deps = re.findall(r"pbvbus::(\w+)", link.group(1)) if link else []
            targets[name] = (rel, deps)
    return targets


def documented():
    """[(floor index, name, folder, [deps])] from the ```layers block, top floor first."""
    text = (ROOT / "docs/architecture.md").read_text()
    m = re.search(r"```layers\n(.*?)```", text, re.S)
    if not m:
        return None
    floors = []
    for block in m.group(1).split("\n\n"):
        floor = []
        for line in block.strip().splitlines():
            lm = re.match(r"\s*(\w+)\s+\(([\w/]+)\)\s*:?\s*(.*)$", line)
            if lm:
                floor.append((lm.group(1), lm.group(2), lm.group(3).split()))
        if floor:
            floors.append(floor)
    out = []
    for i, floor in enumerate(reversed(floors)):  # bottom floor = 0
        for name, folder, deps in floor:
            out.append((i, name, folder, deps))
    return out


def main():
    problems = []
    targets = cmake_targets()
    doc = documented()
    if doc is None:
        print("docs/architecture.md has no ```layers block")
        return 1
    floor_of = {name: f for f, name, _, _ in doc}
    doc_by_name = {name: (folder, deps) for _, name, folder, deps in doc}
    for name, (folder, deps) in sorted(targets.items()):
        if name not in doc_by_name:
            problems.append(f"target {name} ({folder}) is not in the picture")
            continue
        dfolder, ddeps = doc_by_name[name]
        if dfolder != folder:
            problems.append(f"target {name}: folder {folder}, the picture says {dfolder}")
        if sorted(set(deps)) != sorted(set(ddeps)):
            problems.append(f"target {name}: CMake deps {sorted(set(deps))}, the picture says {sorted(set(ddeps))}")
        for d in deps:
            if d in floor_of and floor_of[d] >= floor_of[name]:
                problems.append(f"target {name} (floor {floor_of[name]}) depends on {d} (floor {floor_of[d]}): not downward")
    for name in doc_by_name:
        if name not in targets:
            problems.append(f"the picture names {name}, which CMake does not build")

    def reach(name, seen=None):
        seen = set() if seen is None else seen
        for d in targets.get(name, ("", []))[1]:
            if d not in seen:
                seen.add(d)
                reach(d, seen)
        return seen

    # Header folder name (include/pbvbus/<x>/) of each target.
    inc_owner = {}
    for name, (folder, _) in targets.items():
        for d in (ROOT / folder / "include/pbvbus").glob("*"):
            inc_owner[d.name] = name
    # A target's folder may hold another target's folder (gateways/ holds gateways/iso_on_tcp):
    # each file belongs to the target with the longest folder that contains it.
    def owner_of(src):
        rel = src.relative_to(ROOT).as_posix()
        best = None
        for n, (f, _) in targets.items():
            if rel.startswith(f + "/") and (best is None or len(f) > len(targets[best][0])):
                best = n
        return best

    for name, (folder, _) in sorted(targets.items()):
        allowed = reach(name) | {name}
        for src in sorted((ROOT / folder).rglob("*.[ch]pp")):
            if owner_of(src) != name:
                continue
            for inc in re.findall(r'#include "pbvbus/(\w+)/', src.read_text()):
                owner = inc_owner.get(inc)
                if owner and owner not in allowed:
                    problems.append(f"{src.relative_to(ROOT)} includes pbvbus/{inc}/ of {owner}, which {name} does not depend on")

    folders = {folder for folder, _ in targets.values()}
    for t in sorted((ROOT / "tests").rglob("*_test.cpp")):
        rel = t.parent.relative_to(ROOT / "tests").as_posix()
        if rel.split("/")[0] in CROSS_CUTTING:
            continue
        if rel not in folders:
            problems.append(f"tests/{rel}/ does not mirror a target's folder")
    for p in problems:
        print(p)
    if not problems:
        print(f"layout: {len(targets)} targets, picture and CMake agree, dependencies point down")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

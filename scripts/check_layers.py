#!/usr/bin/env python3
"""Fails when a product source includes a project header from a layer it may not use.

The layers and what each may include (directly; the rest follows transitively) are the
table below, the same graph as the libraries' links in the CMakeLists (docs/design.md
§1). A component is the longest matching folder prefix. Tests, benchmarks, fuzz
harnesses and examples sit on top and may include anything. Exit status 1 lists every
offending include with its file and line.
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# component: the components it may include directly.
LAYERS = {
    "device_shared": [],
    "volume/core": ["device_shared"],
    "volume/calibration": ["volume/core"],
    "volume/scene": ["volume/calibration"],
    "volume/material": ["volume/scene"],
    "volume/lpv": ["volume/material"],
    "volume/cpu": ["volume/lpv"],
    "volume/reference": ["volume/material"],
    "volume/eval": ["volume/lpv", "volume/reference"],
    "shaders": ["device_shared"],
    "gpu/vk": ["volume/core", "shaders"],
    "gpu/passes": ["gpu/vk", "volume/lpv"],
    "gpu": ["gpu/passes"],
    "backend": ["volume/cpu", "gpu"],
    "editor": ["backend"],
    "editor/ui": ["editor"],
    "apps": ["editor", "backend", "volume/eval"],
}
TOP = ("tests", "bench", "fuzz", "examples")
SOURCE = re.compile(r"\.(h|cpp|glsl|comp|frag|vert)$")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def component(path):
    best = None
    for name in LAYERS:
        if path == name or path.startswith(name + "/"):
            if best is None or len(name) > len(best):
                best = name
    return best


def closure(name, seen=None):
    seen = set() if seen is None else seen
    for dep in LAYERS[name]:
        if dep not in seen:
            seen.add(dep)
            closure(dep, seen)
    return seen


def main():
    problems = []
    for folder in sorted(LAYERS):
        top = os.path.join(ROOT, folder)
        for entry in sorted(os.listdir(top)) if os.path.isdir(top) else []:
            path = os.path.join(folder, entry)
            if not SOURCE.search(entry) or component(path) != folder:
                continue
            allowed = closure(folder) | {folder}
            with open(os.path.join(ROOT, path), encoding="utf-8") as source:
                for number, line in enumerate(source, 1):
                    match = INCLUDE.match(line)
                    if not match:
                        continue
                    target = component(match.group(1))
                    if match.group(1).startswith(TOP) or (target is not None and target not in allowed):
                        problems.append(f"{path}:{number}: {folder} may not include {match.group(1)}")
    for problem in problems:
        print(problem)
    if problems:
        print(f"check_layers: {len(problems)} include(s) against the layers in scripts/check_layers.py")
        return 1
    print(f"check_layers: every include follows the layers ({len(LAYERS)} components)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Checks the layering of docs/design.md: a file under wavetrace/LAYER/ includes only from its
own layer and the layers below it, and no two concepts (a NAME.hpp with its NAME.cpp) include
each other, directly or round a circle. Also that no code but the accelerator registry
(wavetrace/accel/registry.cpp) compares an accelerator type's name: its row holds every fact
about a type. Prints each violation and exits 1; exits 0 silently."""
import pathlib
import re
import sys

# Lowest first: a layer may include from itself and from those before it.
LAYERS = ["kernels", "memory", "scene", "accel", "stages", "pipeline", "setup", "distribute", "bench"]
TYPE_NAMES = ("embree", "bvh", "raystrips", "hmq", "grid", "mlgrid", "arraygrid", "tinybvh")
TYPE_COMPARISON = re.compile(r'[=!]=\s*"(' + "|".join(TYPE_NAMES) + r')"|"(' + "|".join(TYPE_NAMES) + r')"\s*[=!]=')
REGISTRY = pathlib.PurePath("accel/registry.cpp")
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]wavetrace/([a-z_]+)/([^>"]+)[>"]', re.M)


def concept(path: pathlib.PurePath) -> str:
    return str(path.with_suffix(""))


def main(root: pathlib.Path) -> int:
    problems = []
    graph: dict[str, set[str]] = {}
    for path in sorted((root / "wavetrace").rglob("*.[ch]pp")):
        relative = path.relative_to(root / "wavetrace")
        layer = relative.parts[0]
        if layer not in LAYERS:
            continue
        node = concept(relative)
        graph.setdefault(node, set())
        text = path.read_text()
        if relative != REGISTRY:
            for number, line in enumerate(text.splitlines(), 1):
                if TYPE_COMPARISON.search(line):
                    problems.append(f"wavetrace/{relative}:{number}: compares an accelerator type's name "
                                    "(ask its row in accel/registry.hpp)")
        for match in INCLUDE.finditer(text):
            target_layer, target = match.group(1), match.group(2)
            if target_layer not in LAYERS:
                problems.append(f"wavetrace/{relative}: includes wavetrace/{target_layer}/{target}, which is no layer")
                continue
            if LAYERS.index(target_layer) > LAYERS.index(layer):
                problems.append(f"wavetrace/{relative}: includes wavetrace/{target_layer}/{target} "
                                f"({target_layer} is above {layer})")
            target_node = concept(pathlib.PurePath(target_layer) / target)
            if target_node != node:
                graph[node].add(target_node)

    # Circles between concepts: depth-first search, reporting each circle once.
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []
    circles = set()

    def visit(node: str) -> None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                circle = path[path.index(nxt):]
                start = circle.index(min(circle))
                circles.add(tuple(circle[start:] + circle[:start]))
            elif nxt not in state:
                visit(nxt)
        path.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)
    for circle in sorted(circles):
        problems.append("includes run in a circle: " + " -> ".join(circle + (circle[0],)))

    for problem in problems:
        print(problem)
    return 1 if problems else 0


def self_test() -> int:
    """The check itself fails on what it exists to catch: an include from a lower layer to a
    higher one, and two concepts including each other through a .cpp."""
    import contextlib
    import io
    import tempfile

    cases = {
        "upward": {"stages/a.hpp": '#include "wavetrace/setup/b.hpp"\n', "setup/b.hpp": ""},
        "circle": {"setup/a.hpp": "", "setup/a.cpp": '#include "wavetrace/setup/b.hpp"\n',
                   "setup/b.hpp": '#include "wavetrace/setup/a.hpp"\n'},
        "type_name": {"setup/a.cpp": 'bool f(const std::string& t) { return t == "hmq"; }\n'},
        "clean": {"stages/a.hpp": "", "setup/b.hpp": '#include <wavetrace/stages/a.hpp>\n',
                  "accel/registry.cpp": 'bool g(const std::string& t) { return t == "hmq"; }\n'},
    }
    failures = 0
    for name, files in cases.items():
        with tempfile.TemporaryDirectory() as root:
            for relative, text in files.items():
                path = pathlib.Path(root) / "wavetrace" / relative
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text)
            with contextlib.redirect_stdout(io.StringIO()):
                status = main(pathlib.Path(root))
        if status != (0 if name == "clean" else 1):
            print(f"self-test: the {name} tree gave status {status}")
            failures += 1
    return 1 if failures else 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    sys.exit(main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)))

"""The package layout as a checked contract (docs/internals.md, "The layout").

Every ``compliance`` package imports only from packages below it in ``LAYERS`` (a subpackage
such as ``diagnosis/servo`` is on its parent's layer), reads no resource of a higher package
through ``importlib.resources``; no module imports itself back through a cycle, the rooms of one
package (its subpackages and its own top level) import each other without a cycle, and no
folder holds more than ``MAX_FOLDER_MODULES`` modules. These read the source with ``ast`` (nothing is run), so
a lazy import inside a function counts like any other.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "compliance"

# bottom first: a package may import from itself and from packages before it in this list
LAYERS = ["version", "errors", "processes", "units", "files", "physics", "effects", "model", "simulation", "plants",
          "metrics", "linear", "tracking", "procedures", "requirements", "presentation", "results", "campaign", "sweep",
          "recordings", "validation", "characterise", "diagnosis", "acceptance", "report", "papers", "model_evidence",
          "pipeline", "cli", "__main__"]


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """Modules of ``compliance`` that ``name`` imports (resolved to existing modules)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            targets = [f"{node.module}.{a.name}" for a in node.names]
        for t in targets:
            while t and t not in modules:
                t = t.rpartition(".")[0]
            if t.startswith("compliance") and t != name:
                found.add(t)
    return found


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None  # None: the root package (version, numba cache)


def test_every_package_is_placed_in_the_layers():
    tops = {_layer(m) for m in _modules()} - {None}
    assert tops <= set(LAYERS), f"packages missing from LAYERS: {sorted(tops - set(LAYERS))}"


def test_packages_import_only_downwards():
    rank = {name: i for i, name in enumerate(LAYERS)}
    upward = []
    for module, deps in _graph().items():
        here = _layer(module)
        for dep in deps:
            there = _layer(dep)
            if here is None or there is None or here == there:
                continue
            if rank[there] > rank[here]:
                upward.append(f"{module} -> {dep}")
    assert not upward, "imports against the layer order:\n" + "\n".join(sorted(upward))


def test_no_import_cycles():
    graph = _graph()
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles, f"import cycles: {cycles}"


# compiled kernels kept whole because splitting them measurably cost speed (the reason and the
# figures stand in a comment above each)
LONG_COMPILED = {("compliance.model.assembly", "plant_rhs")}
MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 80


def test_modules_and_functions_stay_small():
    too_big = []
    for name, path in _modules().items():
        text = path.read_text()
        if text.count("\n") > MAX_MODULE_LINES:
            too_big.append(f"{name}: {text.count(chr(10))} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES and (name, node.name) not in LONG_COMPILED:
                    too_big.append(f"{name}.{node.name}: {n} lines")
    assert not too_big, "over the size limits (docs/internals.md):\n" + "\n".join(too_big)


# a folder a newcomer can take in at a glance. A catalogue is read by name and grows with what it
# lists, so it may hold more: effects/ (one module per declared effect, plus base, param, catalogue)
# and cli/ (one module per command, plus the shared option helpers)
MAX_FOLDER_MODULES = 15
FOLDER_EXCEPTIONS = {"compliance/effects", "compliance/cli"}


def test_no_folder_holds_too_many_modules():
    crowded = []
    for folder in sorted({p.parent for p in PACKAGE.rglob("*.py")}):
        n = sum(1 for p in folder.glob("*.py") if p.name != "__init__.py")
        name = folder.relative_to(PACKAGE.parent).as_posix()
        if n > MAX_FOLDER_MODULES and name not in FOLDER_EXCEPTIONS:
            crowded.append(f"{name}: {n} modules")
    assert not crowded, f"folders over {MAX_FOLDER_MODULES} modules (split them into rooms by job):\n" + "\n".join(crowded)


def _resource_packages(path: Path) -> set[str]:
    """``compliance`` packages whose files a module reads through ``importlib.resources``."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call):
            f = node.func
            fname = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if fname in ("files", "open_text", "open_binary", "read_text", "read_binary", "path", "contents",
                         "is_resource") and node.args:
                arg = node.args[0]
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str) and arg.value.startswith("compliance"):
                    found.add(arg.value)
    return found


def test_no_resources_read_from_a_higher_layer():
    rank = {name: i for i, name in enumerate(LAYERS)}
    upward = []
    for module, path in _modules().items():
        here = _layer(module)
        for package in _resource_packages(path):
            there = _layer(package)
            if here is not None and there is not None and there != "data" and rank.get(there, -1) > rank[here]:
                upward.append(f"{module} reads resources of {package}")
    assert not upward, "resources read against the layer order:\n" + "\n".join(sorted(upward))


def _room(path: Path) -> str:
    """The folder a module sits in (``compliance.diagnosis.servo``; a package's ``__init__`` is its own folder)."""
    return ".".join(path.parent.relative_to(PACKAGE.parent).parts)


def test_rooms_of_a_package_form_no_cycle():
    modules, rooms = _modules(), {}
    for module, deps in _graph().items():
        if _layer(module) is None:
            continue
        here = _room(modules[module])
        rooms.setdefault(here, set())
        for dep in deps:
            there = _room(modules[dep])
            if there != here and _layer(dep) == _layer(module):
                rooms[here].add(there)
    cycles = []
    for start in rooms:  # rooms are few: a depth-first search from each finds any way back
        seen, todo = set(), list(rooms[start])
        while todo:
            r = todo.pop()
            if r == start:
                cycles.append(start)
                break
            if r not in seen:
                seen.add(r)
                todo.extend(rooms.get(r, ()))
    assert not cycles, f"rooms that import themselves back through another room: {sorted(cycles)}"


def test_the_kept_long_kernels_say_why():
    for module, func in LONG_COMPILED:
        text = (PACKAGE.parent / (module.replace(".", "/") + ".py")).read_text()
        head = text[: text.index(f"def {func}(")]
        assert "split" in head[-1500:], f"{module}.{func}: the comment with the measured reason is missing"


def _module_names(tree: ast.Module) -> set[str]:
    """Names a module binds to imported modules (``import x``, ``import x as y``, ``from p import m``)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
    return names


def _makes_names(node: ast.AST, modules: set[str]) -> bool:
    """A call that creates names invisible to grep: ``globals()``, bare ``vars()``, ``setattr`` on a module."""
    if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Name):
        return False
    if node.func.id == "globals" or (node.func.id == "vars" and not node.args):
        return True
    if node.func.id == "setattr" and node.args:
        target = node.args[0]
        if isinstance(target, ast.Name) and target.id in modules:
            return True
        text = ast.unparse(target)
        return "sys.modules" in text or "import_module" in text or "__import__" in text
    return False


def test_no_module_makes_names_through_globals():
    """Every name of the package is written out where it is defined (grep and IDEs find it)."""
    found = []
    for name, path in _modules().items():
        tree = ast.parse(path.read_text())
        modules = _module_names(tree)
        found += [f"{name}:{n.lineno}: {ast.unparse(n)[:60]}" for n in ast.walk(tree) if _makes_names(n, modules)]
    assert not found, "names made at run time (write them out instead):\n" + "\n".join(found)


def test_the_rule_sees_globals_and_setattr_on_a_module():
    src = "import sys\nimport numpy as np\nglobals()['A'] = 1\nsetattr(sys.modules[__name__], 'B', 2)\nsetattr(np, 'C', 3)\nsetattr(obj, 'd', 4)\n"
    tree = ast.parse(src)
    hits = [n.lineno for n in ast.walk(tree) if _makes_names(n, _module_names(tree))]
    assert sorted(hits) == [3, 4, 5]  # setattr on an object is not a module name


# the one executor (compliance/processes/): nothing else starts processes, counts cores or maps tasks
_POOL_NAMES = ("ProcessPoolExecutor", "multiprocessing", "worker_pool", "sched_getaffinity", "cpu_count")


def test_one_process_pool_implementation():
    found = []
    for name, path in _modules().items():
        if name.startswith("compliance.processes"):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name == "map_tasks":
                found.append(f"{name}: defines map_tasks")
            elif isinstance(node, ast.Import):
                found += [f"{name}: imports {a.name}" for a in node.names if a.name.split(".")[0] == "multiprocessing"]
            elif isinstance(node, ast.ImportFrom) and node.module:
                found += [f"{name}: imports {node.module}.{a.name}" for a in node.names
                          if node.module.split(".")[0] == "multiprocessing" or a.name in _POOL_NAMES]
            elif isinstance(node, ast.Attribute) and node.attr in _POOL_NAMES:
                found.append(f"{name}: uses .{node.attr}")
    assert not found, "process pools outside compliance/processes (use compliance.processes.map_tasks):\n" + "\n".join(found)


# an effect's slot constants (P_<SHORT>_..., S_<slot>) are read outside effects/ only by the one composition module
# (plant_rhs composes the structural effects' kernels) and two simulator modules (the sampled loop holds sensor_lag's
# filter and the delay lines, the recorder writes the effects' states); everything else goes through the declarations
SLOT_READERS = {"compliance.model.assembly", "compliance.simulation.rk4", "compliance.simulation.pid_loop"}
_SLOT_NAME = re.compile(r"^[PS]_[A-Z0-9_]+$")


def _effect_slot_reads(tree: ast.Module, effect_modules: set[str]) -> list[str]:
    """Slot constants of an effect module that ``tree`` imports or reads through a module alias."""
    found, aliases = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module in effect_modules:
                found += [f"{node.module}.{a.name}" for a in node.names if _SLOT_NAME.match(a.name)]
            aliases |= {a.asname or a.name for a in node.names if f"{node.module}.{a.name}" in effect_modules}
        elif isinstance(node, ast.Import):
            aliases |= {a.asname for a in node.names if a.name in effect_modules and a.asname}
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _SLOT_NAME.match(node.attr):
            base = ast.unparse(node.value)
            if base in aliases or base in effect_modules:
                found.append(f"{base}.{node.attr}")
    return found


def _effect_module_names() -> set[str]:
    return {m for m in _modules() if m.startswith("compliance.effects.")}


def test_effect_slots_are_read_by_at_most_three_modules_outside_effects():
    effect_modules = _effect_module_names()
    readers = {}
    for name, path in _modules().items():
        if _layer(name) == "effects":
            continue
        reads = _effect_slot_reads(ast.parse(path.read_text()), effect_modules)
        if reads:
            readers[name] = reads
    assert len(SLOT_READERS) <= 3
    stray = {m: r for m, r in readers.items() if m not in SLOT_READERS}
    assert not stray, ("effect slot constants read outside effects/ (use the declarations and the hooks of "
                       "compliance.effects.structure instead):\n" + "\n".join(f"{m}: {', '.join(r)}" for m, r in stray.items()))


def test_the_slot_rule_sees_imports_and_module_aliases():
    src = ("from compliance.effects.heat_transfer import S_TA, wall_heat_flow\n"
           "from compliance.effects import supply_droop\nimport compliance.effects.sensor_lag as sl\n"
           "a = supply_droop.P_SD_ON + sl.P_SL_TAU + supply_droop.reservoir_pressure_rate\n")
    found = _effect_slot_reads(ast.parse(src), _effect_module_names())
    assert sorted(found) == ["compliance.effects.heat_transfer.S_TA", "sl.P_SL_TAU", "supply_droop.P_SD_ON"]


# a plant kind is a room (compliance/plants, docs/internals.md "Adding a plant kind"): nothing outside it reads
# controller.type, and the package switches on a kind's name in at most MAX_KIND_SWITCHES places
KIND_NAMES = {"pid", "state_feedback"}
MAX_KIND_SWITCHES = 6


def _constants(node: ast.AST) -> set:
    if isinstance(node, ast.Constant):
        return {node.value}
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return {e.value for e in node.elts if isinstance(e, ast.Constant)}
    return set()


def _kind_switches(tree: ast.Module) -> list[tuple[int, str]]:
    """(line, what) of every plant-kind switch: a read of ``controller.type``, a comparison with a kind's name,
    a table keyed by the kinds' names, an effect flag for one plant."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript) and "controller.type" in _constants(node.slice):
            found.append((node.lineno, "reads controller.type"))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "get"
              and node.args and "controller.type" in _constants(node.args[0])):
            found.append((node.lineno, "reads controller.type"))
        elif isinstance(node, ast.Compare) and KIND_NAMES & set().union(*map(_constants, [node.left, *node.comparators])):
            found.append((node.lineno, "compares with a kind's name"))
        elif isinstance(node, ast.Dict) and KIND_NAMES <= {k.value for k in node.keys if isinstance(k, ast.Constant)}:
            found.append((node.lineno, "a table keyed by the kinds"))
        elif (isinstance(node, ast.Attribute) and node.attr == "plant_b") or (isinstance(node, ast.keyword) and node.arg == "plant_b"):
            found.append((node.lineno, "an effect flag for one plant"))
    return found


def test_plant_kinds_are_switched_in_their_room_only():
    switches = {name: _kind_switches(ast.parse(path.read_text())) for name, path in _modules().items()}
    outside = [f"{name}:{line}: {what}" for name, found in switches.items() if not name.startswith("compliance.plants")
               for line, what in found if what == "reads controller.type"]
    assert not outside, "controller.type read outside compliance/plants (ask plants.kind_of(cfg)):\n" + "\n".join(outside)
    total = [f"{name}:{line}: {what}" for name, found in switches.items() for line, what in found]
    assert len(total) <= MAX_KIND_SWITCHES, "plant-kind switches (give the kind a method instead):\n" + "\n".join(total)


def test_the_kind_rule_sees_reads_comparisons_and_tables():
    src = ('a = cfg.options["controller.type"]\nb = o.get("controller.type", "pid")\nif m == "pid": pass\n'
           'if m in ("state_feedback",): pass\nT = {"pid": 1, "state_feedback": 2}\nS = {"pid": True}\n'
           'E = Effect(plant_b=False)\nname = "pid"\n')
    assert sorted(line for line, _ in _kind_switches(ast.parse(src))) == [1, 2, 3, 4, 5, 7]

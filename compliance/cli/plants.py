"""``govcheck plants``: list the reference plant configurations shipped with govcheck."""

from __future__ import annotations

from compliance.files.shipped import shipped_names
from compliance.model.config import load_plant


def register(sub):
    from compliance.cli.common import add_parser

    p = add_parser(sub, "plants", help="list the reference plant configurations",
                   description="List the reference configurations shipped with govcheck, usable as CONFIG by name "
                               "(govcheck check plant-a ...) or copied from models/ and edited.",
                   examples=["govcheck plants", "govcheck simulate plant-a --duration 5 -o run.csv"])
    return p


def run(args) -> int:
    for name in shipped_names("plant"):
        cfg = load_plant(name)
        arr = cfg.options["cylinder.arrangement"]
        print(f"{name:10s} {arr:7s} stroke {cfg.p('cylinder.stroke')*1e3:.0f} mm, bore {cfg.p('cylinder.piston_diameter')*1e3:.0f} mm, "
              f"supply {cfg.p('air.supply_pressure')/1e5:.2f} bar abs  - {cfg.description}")
    return 0

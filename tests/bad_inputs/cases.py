"""The bad-input catalogue: one spoilt input per case, the exit code and a fragment of the message.

A case is ``(id, files, argv, fragment)`` (exit code 2 unless given): ``files`` are written into
a fresh good workspace (``workspace.build``) before the run - text, bytes, or a function of the
workspace folder - and ``argv`` is the govcheck command line, run in that folder. Every case must
exit with its code, print one message containing the fragment, no traceback, and leave the
workspace byte-for-byte as it was (nothing written, nothing changed).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tests.bad_inputs import workspace as W


@dataclass
class Case:
    id: str
    files: dict
    argv: list
    fragment: str
    code: int = 2
    env: dict = field(default_factory=dict)


CASES: list[Case] = []


def case(id, argv, fragment, files=None, code=2, env=None):
    CASES.append(Case(id, files or {}, argv.split() if isinstance(argv, str) else argv, fragment, code, env or {}))


def file_cases(argv, name, rows):
    """One case per ``(id, text of the file NAME, fragment)`` row, all run with ``argv``."""
    for cid, text, frag in rows:
        case(cid, argv, frag, {name: text})


def plant(old, new):
    """Plant A with one line changed (the old text must be there)."""
    assert old in W.PLANT_A, old
    return W.PLANT_A.replace(old, new, 1)


def req(old, new):
    """The tiny requirement file with one text changed."""
    assert old in W.REQUIREMENTS, old
    return W.REQUIREMENTS.replace(old, new, 1)


def cols(**changes):
    """The good recording with some columns changed by functions of the column array."""
    c = W.recording_columns()
    for name, fn in changes.items():
        c[name] = fn(c[name].copy()) if callable(fn) else fn
    return c


def spike(a, i=120, v=1e300):
    a[i] = v
    return a


def nan_at(a, i=50):
    a[i] = np.nan
    return a


def backwards(a, i=100):
    a[i] = a[i - 2]
    return a


def drop(name):
    c = W.recording_columns()
    del c[name]
    return c


# ------------------------------------------------------------------------------------- configs
CHECK = "check bad.toml -r req.toml --json out/r.json -q"
file_cases(CHECK, "bad.toml", [
    ("config-malformed-toml", "name = 'x\n[cylinder\n", "bad.toml"),
    ("config-empty", "", "bad.toml"),
    ("config-not-utf8", b"\xff\xfe\x00bad", "bad.toml"),
    ("config-missing-stroke", plant('stroke = { value = "160 mm", source = "paper" }\n', ""), "stroke"),
    ("config-negative-bore", plant('"125 mm"', '"-125 mm"'), "piston_diameter"),
    ("config-zero-stroke", plant('"160 mm"', '"0 mm"'), "stroke"),
    ("config-wrong-unit", plant('"160 mm"', '"160 kg"'), "stroke"),
    ("config-unknown-unit", plant('"160 mm"', '"160 furlongs_per_fortnight"'), "stroke"),
    ("config-pressure-no-abs", plant('"8.0 bar abs"', '"8.0 bar"'), "supply_pressure"),
    ("config-negative-mass", plant('"30 kg"', '"-30 kg"'), "moving_mass"),
    ("config-nan-mass", plant('"30 kg"', '"nan kg"'), "moving_mass"),
    ("config-text-number", plant('value = 1.4,', 'value = "lots",'), "heat_capacity_ratio"),
    ("config-unknown-key", plant('moving_mass =', 'moving_mas = { value = "1 kg", source = "paper" }\nmoving_mass ='), "moving_mas"),
    ("config-unknown-section", W.PLANT_A + "\n[cylindre]\nstroke = 1\n", "cylindre"),
    ("config-unknown-flow-law", plant('flow_law = "iso6358"', 'flow_law = "magic"'), "magic"),
    ("config-unknown-friction-model", plant('model = "lugre"', 'model = "glue"'), "glue"),
    ("config-unknown-arrangement", plant('arrangement = "tandem"', 'arrangement = "triple"'), "triple"),
    ("config-rod-wider-than-bore", plant('"32 mm"', '"200 mm"'), "rod"),
    ("config-load-curve-lengths", plant("values = [0, 15, 40, 70, 85, 100]", "values = [0, 15, 40]"), "curve"),
    ("config-negative-gain", plant('"280 V/m"', '"-280 V/m"'), "kp"),
    ("config-zero-sample-time", plant('sample_time = { value = "1 ms"', 'sample_time = { value = "0 ms"'), "sample_time"),
    ("config-step-too-large", plant('step = { value = "1 ms"', 'step = { value = "1 s"'), "step"),
    ("config-conductance-unit", plant('"0.794 dm^3/(s*bar)"', '"0.794 bar"'), "opening_conductance"),
    ("config-critical-ratio-above-1", plant("critical_pressure_ratio = { value = 0.528", "critical_pressure_ratio = { value = 1.5"), "critical_pressure_ratio"),
])
case("config-missing-file", "check nothere.toml -r req.toml -q", "nothere.toml")
case("config-is-folder", "check out -r req.toml -q", "out")
case("config-unknown-reference", "check plant-z -r req.toml -q", "plant-z")
case("config-none-given", "check -r req.toml -q", "no plant configuration given")

# ------------------------------------------------------------------------------------- requirements
CHECKR = "check plant.toml -r bad-req.toml --json out/r.json -q"
file_cases(CHECKR, "bad-req.toml", [
    ("req-malformed-toml", "schema = \n", "bad-req.toml"),
    ("req-wrong-schema", req('schema = "govcheck-requirements/1"', 'schema = "govcheck-requirements/9"'), "schema"),
    ("req-unknown-metric", req('metric = "time_constant"', 'metric = "time_konstant"'), "time_konstant"),
    ("req-unknown-comparator", req('comparator = "within"', 'comparator = "about"'), "about"),
    ("req-bare-number-limit", req('limit = ["0.10 s", "0.25 s"]', 'limit = [0.1, 0.25]'), "limit"),
    ("req-wrong-unit-limit", req('limit = ["0.10 s", "0.25 s"]', 'limit = ["0.10 mm", "0.25 mm"]'), "limit"),
    ("req-within-one-value", req('limit = ["0.10 s", "0.25 s"]', 'limit = "0.25 s"'), "within"),
    ("req-low-above-high", req('limit = ["0.10 s", "0.25 s"]', 'limit = ["0.25 s", "0.10 s"]'), "above"),
    ("req-negative-limit", req('comparator = "within"\nlimit = ["0.10 s", "0.25 s"]', 'comparator = "<="\nlimit = "-1 s"'), "negative"),
    ("req-negative-low-limit", req('limit = ["0.10 s", "0.25 s"]', 'limit = ["-0.10 s", "0.25 s"]'), "negative"),
    ("req-missing-limit", req('limit = ["0.10 s", "0.25 s"]\n', ''), "limit"),
    ("req-missing-metric", req('metric = "time_constant"\n', ''), "metric"),
    ("req-unknown-operating-point", req('operating_points = ["mid"]', 'operating_points = ["middle"]'), "middle"),
    ("req-unknown-procedure", req('procedures = ["steps-5"]', 'procedures = ["steps-50"]'), "steps-50"),
    ("req-unknown-kind", req('kind = "steps"', 'kind = "jumps"'), "jumps"),
    ("req-unknown-stroke-start", req('kind = "steps"\ntitle = "5 % steps"\nsize = "5 %stroke"',
                                     'kind = "full_stroke"\ntitle = "stroke"\nstart = "middle"'), "procedures.steps-5.start"),
    ("req-metric-not-measurable", req('metric = "time_constant"', 'metric = "opening_time"'), "cannot be measured"),
    ("req-unknown-severity", req('severity = "mandatory"', 'severity = "optional"'), "optional"),
    ("req-extends-missing", req('name = "tiny"', 'name = "tiny"\nextends = "nothere.toml"'), "nothere.toml"),
    ("req-no-requirements", W.REQUIREMENTS.split("[requirements.TC]")[0], "no requirements"),
    ("req-step-size-unit", req('size = "5 %stroke"', 'size = "5 kg"'), "size"),
    ("req-position-outside", req('initial_position = "50 %stroke"', 'initial_position = "150 %stroke"'), "stroke"),
    ("req-load-unit", req('load = "none"', 'load = "12 m"'), "load"),
])
case("req-missing-file", "check plant.toml -r nothere.toml -q", "nothere.toml")
case("req-unknown-reference", "check plant.toml -r iec99999 -q", "iec99999")

# ------------------------------------------------------------------------------------- recordings
VAL = "validate plant.toml bad.csv --json out/v.json"
for cid, text, frag in [
    ("csv-no-header", W.csv_text().split("\n", 1)[1], "bad.csv"),
    ("csv-non-numeric", W.csv_text().replace("\n0.05,", "\n0.05x,", 1), "not a number"),
    ("csv-time-backwards", W.csv_text(cols(time=backwards)), "not strictly increasing"),
    ("csv-nan", W.csv_text(cols(position=nan_at)), "NaN"),
    ("csv-inf", W.csv_text(cols(pressure_a=lambda a: spike(a, 10, np.inf))), "NaN/empty/infinite"),
    ("csv-spike-1e300", W.csv_text(cols(position=spike)), "outside"),
    ("csv-spike-late-pressure", W.csv_text(cols(pressure_b=lambda a: spike(a, 190, 1e12))), "pressure_b"),
    ("csv-negative-abs-pressure", W.csv_text(cols(pressure_a=lambda a: a - 7e5)), "gauge"),
    ("csv-command-kV", W.csv_text(cols(valve_command=lambda a: spike(a, 60, 5000.0))), "valve_command"),
    ("csv-time-in-ms-vs-sidecar", W.csv_text(cols(time=lambda a: a * 1e3)), "milliseconds"),
    ("csv-missing-column", W.csv_text(drop("position")), "position"),
    ("csv-one-sample", "time,position,reference,valve_command\n0,0.08,0.08,0\n", "at least 2 samples"),
    ("csv-empty", "", "bad.csv"),
    ("csv-ragged-row", W.csv_text().replace("\n0.05,", "\n0.05,1,2,3,4,5,6,7,8,", 1), "bad.csv"),
    ("csv-duplicate-time", W.csv_text(cols(time=lambda a: backwards(a, 101) if False else np.concatenate([a[:100], a[99:199]]))), "not strictly increasing"),
]:
    case(cid, VAL, frag, {"bad.csv": text, "bad.toml": W.SIDECAR})
case("csv-sidecar-bad-toml", VAL, "bad.toml", {"bad.csv": W.csv_text(), "bad.toml": "plant = \n"})
case("csv-sidecar-pressure-no-abs", VAL, "supply_pressure", {"bad.csv": W.csv_text(), "bad.toml": W.SIDECAR.replace("supply_pressure = 800000.0", 'supply_pressure = "8 bar"')})
case("csv-sidecar-load-1e9", VAL, "load_force", {"bad.csv": W.csv_text(), "bad.toml": W.SIDECAR.replace("7000.0", "1e9")})
case("csv-sidecar-rate-1000x", VAL, "sample_time", {"bad.csv": W.csv_text(), "bad.toml": W.SIDECAR.replace("sample_time = 0.001", "sample_time = 1e-6")})
case("csv-ms-no-sidecar", VAL, "milliseconds", {"bad.csv": W.csv_text(cols(time=lambda a: np.round(a * 1e3)))})
case("csv-no-plant-anywhere", "validate bad.csv", "no plant given", {"bad.csv": W.csv_text()})
case("csv-sidecar-unknown-plant", "validate bad.csv", "plant-q", {"bad.csv": W.csv_text(), "bad.toml": W.SIDECAR.replace('"plant-a"', '"plant-q"')})
case("csvgz-corrupt", "validate plant.toml bad.csv.gz", "bad.csv.gz", {"bad.csv.gz": b"\x1f\x8b\x08\x00garbage"})
case("csvgz-spike", "validate plant.toml bad.csv.gz", "outside", {"bad.csv.gz": W.gz(W.csv_text(cols(position=spike))), "bad.toml": W.SIDECAR})
case("recording-missing", "validate plant.toml nothere.csv", "nothere.csv")
case("recording-unknown-format", "validate plant.toml bad.xlsx", "unknown recording format", {"bad.xlsx": b"PK\x03\x04"})
case("recording-is-config", "validate plant.toml plant.toml", "plant configuration in the place")
MAPPED = "validate plant.toml bad.txt --column-map map.toml --mode plant_only --json out/v.json"
mapped_ok = "t_ms,x_mm,u_V,pA_bar\n" + "".join(f"{i},{80 + 1e-3*i:.6f},0.01,4.9\n" for i in range(200))
case("map-unknown-unit", MAPPED.replace("map.toml", "badmap.toml"), "blorp", {"bad.txt": mapped_ok, "badmap.toml": W.COLUMN_MAP.replace('unit = "mm"', 'unit = "blorp"')})
case("map-parsec-for-mm", MAPPED.replace("map.toml", "badmap.toml"), "outside", {"bad.txt": mapped_ok, "badmap.toml": W.COLUMN_MAP.replace('unit = "mm"', 'unit = "parsec"')})
case("map-missing-column", MAPPED.replace("map.toml", "badmap.toml"), "x_cm", {"bad.txt": mapped_ok, "badmap.toml": W.COLUMN_MAP.replace('"x_mm"', '"x_cm"')})
case("map-bad-toml", MAPPED.replace("map.toml", "badmap.toml"), "badmap.toml", {"bad.txt": mapped_ok, "badmap.toml": "[columns\n"})
case("map-not-found", MAPPED.replace("map.toml", "nomap.toml"), "nomap", {"bad.txt": mapped_ok})
case("map-wrong-time-unit", MAPPED.replace("map.toml", "badmap.toml"), "milliseconds", {"bad.txt": mapped_ok, "bad.toml": W.SIDECAR, "badmap.toml": W.COLUMN_MAP.replace('unit = "ms"', 'unit = "s"')})
case("map-gauge-spike", MAPPED, "pressure_a", {"bad.txt": mapped_ok.replace(",4.9\n", ",4.9e9\n", 1)})

MAT = "validate plant.toml bad.mat --json out/v.json"
for cid, c, frag in [
    ("mat-nan", cols(position=nan_at), "NaN"),
    ("mat-time-backwards", cols(time=backwards), "not strictly increasing"),
    ("mat-spike", cols(position=spike), "outside"),
    ("mat-missing-variable", drop("position"), "position"),
    ("mat-time-in-ms", cols(time=lambda a: a * 1e3), "milliseconds"),
    ("mat-negative-pressure", cols(pressure_b=lambda a: -a), "pressure_b"),
]:
    case(cid, MAT, frag, {"bad.mat": (lambda ws, c=c: W.write_mat(ws / "bad.mat", c)), "bad.toml": W.SIDECAR})
case("mat-not-a-mat-file", MAT, "bad.mat", {"bad.mat": b"this is not MATLAB"})


def mat_structs(*names):
    """A .mat file holding the good recording once per struct name (two runs saved together)."""
    def write(ws):
        from scipy.io import savemat

        savemat(ws / "bad.mat", {n: {k: v.reshape(-1, 1) for k, v in W.recording_columns().items()} for n in names})
    return write


case("mat-two-structs", MAT, "2 structs hold recording fields ('run1', 'run2')",
     {"bad.mat": mat_structs("run1", "run2"), "bad.toml": W.SIDECAR})
case("mat-two-structs-hint", MAT, 'column = "run1.time"', {"bad.mat": mat_structs("run1", "run2"), "bad.toml": W.SIDECAR})
case("mat-char-variable", MAT, "variable 'position' is text ('eighty mm')",
     {"bad.mat": (lambda ws: W.write_mat(ws / "bad.mat", cols(position=np.array("eighty mm")))), "bad.toml": W.SIDECAR})

PQ = "validate plant.toml bad.parquet --json out/v.json"
for cid, c, frag in [
    ("parquet-nan", cols(position=nan_at), "NaN"),
    ("parquet-time-backwards", cols(time=backwards), "not strictly increasing"),
    ("parquet-spike", cols(position=spike), "outside"),
    ("parquet-missing-column", drop("position"), "position"),
    ("parquet-time-in-ms", cols(time=lambda a: a * 1e3), "milliseconds"),
    ("parquet-inf-command", cols(valve_command=lambda a: spike(a, 5, -np.inf)), "infinite"),
]:
    case(cid, PQ, frag, {"bad.parquet": (lambda ws, c=c: W.write_parquet(ws / "bad.parquet", c)), "bad.toml": W.SIDECAR})
case("parquet-corrupt", PQ, "bad.parquet", {"bad.parquet": b"PAR1 not really"})

CT = "validate plant.toml bad.cfg --json out/v.json"
for cid, c, frag, rate in [
    ("comtrade-spike", cols(position=lambda a: spike(a, 120, 2000.0)), "outside", 1000.0),
    ("comtrade-negative-pressure", cols(pressure_a=lambda a: -a), "pressure_a", 1000.0),
    ("comtrade-missing-channel", drop("position"), "position", 1000.0),
    ("comtrade-rate-vs-sidecar", W.recording_columns(), "sample_time", 1.0),
]:
    case(cid, CT, frag, {"bad.cfg": (lambda ws, c=c, rate=rate: W.write_comtrade(ws, "bad", c, rate)), "bad.toml": W.SIDECAR})
case("comtrade-lonely-cfg", CT, "bad", {"bad.cfg": "bench,rig1,1999\n"})


def spoilt_comtrade(ws, spoil, **kw):
    """The good recording as a COMTRADE pair, then one of its files changed by ``spoil(cfg_text, dat_bytes)``."""
    cfg = W.write_comtrade(ws, "bad", W.recording_columns(), **kw)
    dat = ws / "bad.dat"
    text, data = spoil(cfg.read_text(encoding="ascii"), dat.read_bytes())
    cfg.write_text(text, encoding="ascii")
    dat.write_bytes(data)


for cid, kw, spoil, frag in [
    ("comtrade-short-dat", {}, lambda c, d: (c, d[: len(d) // 2]), "shorter than the .cfg declares"),
    ("comtrade-short-binary-dat", {"file_type": "BINARY32", "revision": "2013"},
     lambda c, d: (c, d[:-7]), "shorter than the .cfg declares"),
    ("comtrade-binary-declared-ascii", {"file_type": "BINARY32", "revision": "2013"},
     lambda c, d: (c.replace("BINARY32", "ASCII"), d), "binary data declared ASCII"),
    ("comtrade-secondary-without-ratio", {"ratios": {"pressure_a": (2.0, 1.0)}},
     lambda c, d: (c.replace(",2.0,1.0,S", ",0,0,S"), d), "P/S = S"),
    ("comtrade-ambiguous-primary-secondary", {"ratios": {"pressure_a": (2.0, 1.0)}},
     lambda c, d: (c.replace(",2.0,1.0,S", ",2.0,1.0,X"), d), "cannot be told"),
]:
    case(cid, CT, frag, {"bad.cfg": (lambda ws, s=spoil, kw=kw: spoilt_comtrade(ws, s, **kw)), "bad.toml": W.SIDECAR})
case("comtrade-cff-without-data", "validate plant.toml bad.cff", "DAT ---' section",
     {"bad.cff": "--- file type: CFG ---\nbench,rig1,2013\n", "bad.toml": W.SIDECAR})
case("comtrade-malformed-cfg", CT, "bad", {"bad.cfg": "bench\nnot,a,cfg\n", "bad.dat": "1,0,1\n"})

# ------------------------------------------------------------------------------------- CLI arguments
SIM = "simulate plant.toml -o out/run.csv"
case("sim-negative-step-after-the-end", "simulate plant.toml --steps -5%@99s -o out/run.cfg", "later than --duration")
case("sim-comtrade-dat-suffix", "simulate plant.toml -o out/run.dat", ".cfg, .cff")
for cid, extra, frag in [
    ("sim-duration-1e9", "--duration 1e9", "3600"),
    ("sim-duration-negative", "--duration -1", "positive"),
    ("sim-duration-nan", "--duration nan", "finite"),
    ("sim-duration-wrong-unit", "--duration 10kg", "--duration"),
    ("sim-x0-outside", "--x0 500mm", "outside the stroke"),
    ("sim-x0-wrong-unit", "--x0 5V", "--x0"),
    ("sim-steps-syntax", "--steps 2%", "--steps"),
    ("sim-steps-after-duration", "--steps 2%@12s --duration 10", "later than --duration"),
    ("sim-steps-out-of-stroke", "--steps 90%@1s", "outside the stroke"),
    ("sim-steps-backwards", "--steps 2%@3s,-2%@1s", "backwards"),
    ("sim-command-99V", "--command 99V@1s", "command limit"),
    ("sim-command-after-duration", "--command 3V@20s --duration 5", "later than --duration"),
    ("sim-command-syntax", "--command 3V", "--command"),
    ("sim-load-1e9", "--load 1e9", "largest force"),
    ("sim-load-wrong-unit", "--load 11mm", "--load"),
    ("sim-sine-syntax", "--sine 8mm", "--sine"),
    ("sim-sine-after-duration", "--sine 8mm,1Hz,20s --duration 5", "later than --duration"),
    ("sim-sine-zero-frequency", "--sine 8mm,0Hz", "frequency"),
    ("sim-duration-one-sample", "--duration 1e-9", "two controller samples"),
    ("sim-seed-negative", "--seed -1", "--seed"),
    ("sim-plant-conflict", "--plant plant-b", "two plant configurations"),
]:
    case(cid, f"{SIM} {extra}", frag)
case("check-jobs-zero", "check plant.toml -r req.toml -j 0 -q", "--jobs")
case("check-bad-epoch", "check plant.toml -r req.toml --reproducible -q", "SOURCE_DATE_EPOCH", env={"SOURCE_DATE_EPOCH": "yesterday"})
case("check-unknown-option", "check plant.toml -r req.toml --jsn out/x.json", "--jsn")
case("check-no-requirements-flag", "check plant.toml", "--requirements")
case("gate-negative-margin", "gate plant.toml --baseline out/good.json --max-margin-loss -1", "max-margin-loss")
case("gate-candidate-conflict", "gate plant.toml --candidate plant-b --baseline out/good.json", "two candidates")
case("gate-baseline-not-results", "gate plant.toml --baseline out/good.json", "missing from the results file")
case("gate-baseline-missing", "gate plant.toml --baseline out/none.json", "not found")
case("gate-no-requirements", "gate plant.toml --baseline plant-a", "--requirements")
case("validate-negative-max-windows", "validate plant.toml rec.csv --max-windows -1", "--max-windows")
case("validate-bad-noise", "validate plant.toml rec.csv --noise loud", "loud")
case("validate-settings-missing", "validate plant.toml rec.csv --settings nothere.toml", "nothere.toml")
case("linear-at-above-stroke", "linear plant.toml --at 200%", "outside the stroke")
case("linear-load-too-large", "linear plant.toml --load 1e9", "cannot be held")
case("gate-baseline-folder", "gate plant.toml --baseline a-folder.json", "is a folder")
case("validate-bad-mode", "validate plant.toml rec.csv --mode sideways", "sideways")
case("validate-param-negative-mass", "validate plant.toml rec.csv --param cylinder.moving_mass=-5", "moving_mass")
case("validate-param-unknown", "validate plant.toml rec.csv --param cylinder.mass=5", "not a plant parameter")
case("validate-param-text", "validate plant.toml rec.csv --param cylinder.moving_mass=heavy", "not a number")
case("validate-param-syntax", "validate plant.toml rec.csv --param moving_mass", "KEY=VALUE")
case("validate-pdf-without-report", "validate plant.toml rec.csv --pdf out/v.pdf", "--pdf needs --report")
case("validate-two-recordings", "validate plant.toml rec.csv rec.csv", "one recording at a time")
case("validate-setting-unknown", "validate plant.toml rec.csv --setting limits.bogus=1", "bogus")
case("char-valve-negative-volume", "characterise valve rec.csv --volume=-1L", "--volume")
case("char-valve-volume-unit", "characterise valve rec.csv --volume 1kg", "--volume")
case("char-valve-even-window", "characterise valve rec.csv --volume 1L --window 4", "--window")
case("char-valve-unknown-law", "characterise valve rec.csv --volume 1L --laws magic", "magic")
case("char-valve-not-charging", "characterise valve rec.csv --volume 1L --supply-pressure '8 bar abs' --json out/c.json".split(" ", 6)[:6] + ["8 bar abs", "--json", "out/c.json"], "rec.csv")
def charging_csv(name, columns=("time", "pressure_a"), **kw):
    """A 0.6 s charging (or discharging) record of a 0.5 L volume through plant A's valve (synthetic)."""
    def write(ws):
        from compliance.characterise.charging import synthetic_charging

        opts = dict(volume=5e-4, supply_pressure=8e5, initial_pressure=101325.0, duration=0.6, sample_time=1e-3,
                    delay=0.05, noise_std=300.0, seed=5) | kw
        synthetic_charging("iso6358", {"conductance": 2.33e-8, "critical_ratio": 0.3}, **opts)[list(columns)].to_csv(ws / name, index=False)
    return write


CHARGING = {"charge.csv": charging_csv("charge.csv"),
            "discharge.csv": charging_csv("discharge.csv", initial_pressure=8e5, mode="discharge"),
            "late.csv": charging_csv("late.csv", delay=0.45)}
for cid, argv, frag in [
    ("char-valve-supply-below-chamber", ["charge.csv", "--supply-pressure", "8 psi abs"],
     "above the supply 0.552 bar abs (--supply-pressure)"),
    ("char-valve-exhaust-above-chamber", ["discharge.csv", "--exhaust-pressure", "9 bar abs"],
     "the exhaust 9 bar abs (--exhaust-pressure) is above 'pressure_a'"),
    ("char-valve-mode-contradicts", ["charge.csv", "--mode", "discharge", "--supply-pressure", "8 bar abs"],
     "give --mode charge"),
    ("char-valve-mode-contradicts-discharge", ["discharge.csv", "--mode", "charge", "--supply-pressure", "8 bar abs"],
     "give --mode discharge"),
    ("char-valve-window-swallows-opening", ["late.csv", "--window", "201", "--supply-pressure", "8 bar abs"],
     "the derivative window of 201 samples leaves no samples after the valve opening (t = 0.45 s)"),
    ("char-valve-pressure-column-not-pressure", ["charge.csv", "--pressure-column", "time", "--supply-pressure", "8 bar abs"],
     "'time' is not a pressure"),
]:
    case(cid, ["characterise", "valve", *argv[:1], "--volume", "0.5 L", *argv[1:], "--json", "out/c.json"], frag, CHARGING)

case("char-friction-negative-window", "characterise friction rec.csv --window=-1s --area=1e-3m^2", "--window")
case("char-friction-no-force", ["characterise", "friction", "rec.csv", "--area", "1000 mm^2"], "force")
case("char-friction-min-speed-above-runs",
     ["characterise", "friction", str(W.REPO / "tests" / "data" / "zillen" / "O-ring257_1bar_head1000.csv"),
      "--column-map", "zillen-friction", "--min-speed", "1 m/s", "--json", "out/f.json"],
     "--min-speed 1000 mm/s is above every constant-speed part of the runs")
case("diag-unknown-effect", "diagnose plant.toml rec.csv --effects warp_drive -q", "warp_drive")
case("diag-save-model-exists", "diagnose plant.toml rec.csv --save-model rec.toml", "exists already")
case("diag-save-model-is-the-plant", "diagnose plant.toml rec.csv --save-model plant.toml", "is an input of this run ([CONFIG] RECORDING)")
case("diag-jobs-zero", "diagnose plant.toml rec.csv -j 0", "--jobs")
case("diag-joint-report", "diagnose plant.toml rec.csv rec.csv --report out/j.html", "not available for a joint")
case("diag-joint-scheduler", "diagnose plant.toml rec.csv rec.csv --scheduler ftp://x", "scheduler")
case("diag-joint-same-file", "diagnose plant.toml rec.csv rec.csv", "twice")
case("bench-cases-zero", "diagnose-benchmark --cases 0", "--cases")
case("bench-plant-conflict", "diagnose-benchmark plant-a --plant plant-b", "two plant configurations")
case("bench-practice-no-answers", "diagnose-benchmark --practice out", "ANSWERS.json")
case("bench-unknown-effect", "diagnose-benchmark --effects warp_drive", "warp_drive")
case("report-not-json", "report rec.csv --report out/r.html", "not a JSON")
case("report-wrong-schema", "report out/good.json --report out/r.html", "good.json")
case("report-missing", "report out/none.json", "not found")
case("linear-at-text", "linear plant.toml --at middle", "--at")
case("linear-load-unit", "linear plant.toml --load 5m", "--load")
case("reproduce-plant-b", "reproduce plant-b", "tandem")
# --scheduler: one spelling and one check on every command with parallel work
case("bench-bad-scheduler", "diagnose-benchmark --scheduler local:0", "expected local:N with N >= 1")
case("report-bad-scheduler", "report out/good.json --report out/r.html --scheduler ftp://x", "unknown address scheme")
case("reproduce-scheduler-without-calibrate", "reproduce plant.toml --scheduler local:2", "add --calibrate")

# ------------------------------------------------------------------------------------- output paths
for cid, argv, frag in [
    ("out-check-json-folder", "check plant.toml -r req.toml --json out/a-folder.json -q", "is a folder"),
    ("out-check-pdf-folder", "check plant.toml -r req.toml --pdf out/a-folder.pdf -q", "is a folder"),
    ("out-check-report-folder", "check plant.toml -r req.toml --report out/a-folder.html -q", "is a folder"),
    ("out-check-junit-nodir", "check plant.toml -r req.toml --junit nodir/r.xml -q", "does not exist"),
    ("out-check-json-readonly", "check plant.toml -r req.toml --json out/readonly.json -q", "read-only"),
    ("out-check-json-suffix", "check plant.toml -r req.toml --json out/r.txt -q", ".json"),
    ("out-check-junit-suffix", "check plant.toml -r req.toml --json out/x.json --junit out/x.json -q", ".xml"),
    ("out-check-pdf-nodir-after-good-json", "check plant.toml -r req.toml --json out/good.json --pdf nodir/r.pdf -q", "does not exist"),
    ("out-sim-nodir", "simulate plant.toml -o nodir/x.csv", "does not exist"),
    ("out-sim-suffix", "simulate plant.toml -o out/x.txt", ".csv"),
    ("out-sim-plot-nodir", "simulate plant.toml -o out/good.csv --plot nodir/p.png", "does not exist"),
    ("out-sim-plot-suffix", "simulate plant.toml -o out/good.csv --plot out/p.jpg", ".png"),
    ("out-sim-plot-folder", "simulate plant.toml -o out/x.csv --plot out", "is a folder"),
    ("out-sim-sidecar-clobber", "simulate plant.toml -o plant.csv", "not written by govcheck simulate"),
    ("out-sim-output-folder", "simulate plant.toml -o out/a-folder.json", "is a folder"),
    ("out-validate-report-folder", "validate plant.toml rec.csv --report out/a-folder.html", "is a folder"),
    ("out-validate-json-nodir", "validate plant.toml rec.csv --json nodir/v.json", "does not exist"),
    ("out-diag-save-model-suffix", "diagnose plant.toml rec.csv --save-model out/m.txt", ".toml"),
    ("out-diag-json-readonly", "diagnose plant.toml rec.csv --json out/readonly.json", "read-only"),
    ("out-report-html-folder", "report out/good.json --html out/a-folder.html", "--report out/a-folder.html: is a folder"),
    ("out-report-pdf-nodir", "report out/good.json --pdf nodir/r.pdf", "does not exist"),
    ("out-linear-plot-suffix", "linear plant.toml --plot out/p.gif", ".png"),
    ("out-linear-json-folder", "linear plant.toml --json out/a-folder.json", "is a folder"),
    ("out-linear-governor-json-nodir", "linear plant.toml --governor-json nodir/g.json", "does not exist"),
    ("out-char-plot-suffix", "characterise valve rec.csv --volume 1L --plot out/p.bmp", ".png"),
    ("out-gate-markdown-nodir", "gate plant.toml --baseline out/good.json --markdown nodir/pr.md", "does not exist"),
    ("out-gate-json-folder", "gate plant.toml --baseline out/good.json --json out/a-folder.json", "is a folder"),
    ("out-bench-json-folder", "diagnose-benchmark --json out/a-folder.json", "is a folder"),
    ("out-reproduce-json-nodir", "reproduce plant-a --json nodir/p.json", "does not exist"),
]:
    case(cid, argv, frag)
# ------------------------------------------------------------------------------------- sweep files
SWEEP = '''schema = "govcheck-sweep/1"
name = "tiny"
title = "catalogue sweep"
base = "plant.toml"
requirements = "req.toml"

[search]
method = "grid"

[adjust."controller.kp"]
values = ["280 V/m", "300 V/m"]
'''


def sweep(old, new):
    assert old in SWEEP, old
    return SWEEP.replace(old, new, 1)


SW = "sweep bad-sweep.toml --out out"
file_cases(SW, "bad-sweep.toml", [
    ("sweep-malformed-toml", "schema = \n", "bad-sweep.toml"),
    ("sweep-wrong-schema", sweep('"govcheck-sweep/1"', '"govcheck-sweep/7"'), "schema"),
    ("sweep-unknown-parameter", sweep('"controller.kp"', '"controller.kq"'), "controller.kq"),
    ("sweep-wrong-unit", sweep('"280 V/m", "300 V/m"', '"280 kg", "300 kg"'), "kg"),
    ("sweep-empty-values", sweep('values = ["280 V/m", "300 V/m"]', 'values = []'), "empty"),
    ("sweep-empty-range", sweep('values = ["280 V/m", "300 V/m"]', 'range = ["300 V/m", "280 V/m"]'), "range"),
    ("sweep-negative-gain", sweep('"280 V/m", "300 V/m"', '"-280 V/m", "300 V/m"'), "admissible"),
    ("sweep-base-missing", sweep('base = "plant.toml"', 'base = "nothere.toml"'), "nothere.toml"),
    ("sweep-requirements-missing", sweep('requirements = "req.toml"', 'requirements = "noreq.toml"'), "noreq.toml"),
    ("sweep-no-adjust", SWEEP.split("[adjust")[0], "adjust"),
])
case("sweep-missing-file", "sweep nothere-sweep.toml --out out", "nothere-sweep.toml")
case("sweep-jobs-zero", ["sweep", "bad-sweep.toml", "-j", "0", "--out", "out"], "--jobs", {"bad-sweep.toml": SWEEP})
case("sweep-bad-scheduler", ["sweep", "bad-sweep.toml", "--scheduler", "ftp://x", "--out", "out"], "scheduler", {"bad-sweep.toml": SWEEP})
case("sweep-samples-zero", ["sweep", "bad-sweep.toml", "--samples", "0", "--out", "out"], "--samples", {"bad-sweep.toml": SWEEP})

# ------------------------------------------------------------------------- remedies options, duties, catalogues
DUTY = '''schema = "govcheck-duty/1"
name = "sized"
stroke = "160 mm"
supply_pressure = "8 bar abs"
[load.curve]
position = { values = [0, 100], unit = "percent" }
force = { values = [2.0, 12.0], unit = "kN" }
'''
file_cases("size req.toml --duty duty.toml --out out/sized.toml", "duty.toml", [
    ("duty-wrong-schema", DUTY.replace("govcheck-duty/1", "govcheck-duty/9"), "schema"),
    ("duty-pressure-without-abs", DUTY.replace('"8 bar abs"', '"8 bar"'), "supply_pressure"),
    ("duty-unknown-field", DUTY + 'strokes = "1 m"\n', "strokes"),
    ("duty-decreasing-positions", DUTY.replace("[0, 100]", "[100, 0]"), "increasing"),
])
case("size-missing-duty", "size req.toml --duty nothere-duty.toml", "nothere-duty.toml")
case("check-save-remedy-without-remedies", "check plant.toml -r req.toml --save-remedy out/r.toml", "--remedies")
case("check-remedies-bad-catalogue", "check plant.toml -r req.toml --remedies --catalogue cat.toml", "gearbox",
     {"cat.toml": 'schema = "govcheck-hardware/1"\n[options.x]\ngroup = "gearbox"\ntitle = "t"\ncost = 1\n'
                  'sets = { "cylinder.stroke" = "1 m" }\n'})
case("check-remedies-negative-yield", ["check", "plant.toml", "-r", "req.toml", "--remedies", "--yield-units", "-1"], "--yield-units")

# ------------------------------------------------------------------------------------- issue 28: inputs as people have them
BOM = "\ufeff"
VALS = "validate plant.toml s.csv --json out/v.json"


def side(old, new):
    """The good sidecar with one text changed."""
    assert old in W.SIDECAR, old
    return W.SIDECAR.replace(old, new, 1)


def epoch_ms_csv() -> str:
    lines = W.csv_text().splitlines()
    return "\n".join([lines[0]] + [f"{1709648521000 + i}," + line.split(",", 1)[1] for i, line in enumerate(lines[1:])]) + "\n"


def gap(a):
    return np.concatenate([a[:100], a[150:] + 0.0])


for cid, csv, sidecar, frag in [
    # a wrong cause was named: the likely slip is named instead
    ("side-unknown-key-did-you-mean", W.csv_text(), side("load_force", "load_forse"), "did you mean 'load_force'"),
    ("side-unknown-table", W.csv_text(), W.SIDECAR + "[conditons]\nx = 1\n", "did you mean 'conditions'"),
    ("side-load-in-tonnes", W.csv_text(), side("7000.0", '"0.7 t"'), "is a mass"),
    ("side-load-omitted", W.csv_text(), side("load_force = 7000.0\n", ""), "load is not given"),
    ("csv-pressure-in-bar", W.csv_text(cols(pressure_a=lambda a: a / 1e5, pressure_b=lambda a: a / 1e5)), W.SIDECAR,
     "pressure_a' median 5.9 Pa abs - looks like bar without a unit"),
    ("csv-pressure-in-kpa", W.csv_text(cols(supply_pressure=lambda a: a / 1e3)), W.SIDECAR, "looks like kPa without a unit"),
    ("side-sample-time-in-hz", W.csv_text(), side("sample_time = 0.001", "sample_time = 1000.0"), "looks like a rate in Hz"),
    ("csv-position-in-mm", W.csv_text(cols(position=lambda a: a * 1e3, reference=lambda a: a * 1e3)), W.SIDECAR, "millimetres"),
    ("side-is-a-plant", W.csv_text(), W.PLANT_A, "this is a plant configuration, not a recording sidecar"),
    ("side-bom-and-unknown-key", W.csv_text(), BOM + side("load_force", "lod_force"), "did you mean 'load_force'"),
    # silently accepted before
    ("csv-time-gap", W.csv_text(cols(**{k: gap for k in W.recording_columns()})), W.SIDECAR, "samples are missing"),
    ("side-kp-in-v-per-mm", W.csv_text(), side("kp = 280.0", "kp = 0.28"), "V/mm written as V/m"),
    ("side-start-contradicts-recording", W.csv_text(), side("initial_position = 0.08", "initial_position = 0.12"),
     "contradicts the recording"),
    ("side-supply-bar-without-unit", W.csv_text(), side("supply_pressure = 800000.0", "supply_pressure = 8.0"),
     "looks like bar without a unit"),
    ("csv-epoch-milliseconds", epoch_ms_csv(), W.SIDECAR,
     "Unix time in milliseconds"),
]:
    case(cid, VALS, frag, {"s.csv": csv, "s.toml": sidecar})
case("map-zero-gain", MAPPED.replace("map.toml", "badmap.toml"), "gain = 0",
     {"bad.txt": mapped_ok, "badmap.toml": W.COLUMN_MAP.replace('unit = "mm" }', 'unit = "mm", gain = 0 }')})
case("map-is-a-sidecar", MAPPED.replace("map.toml", "rec.toml"), "this is a recording sidecar, not a column map", {"bad.txt": mapped_ok})
case("map-unknown-metadata-key", MAPPED.replace("map.toml", "badmap.toml"), "did you mean 'bore'",
     {"bad.txt": mapped_ok, "badmap.toml": W.COLUMN_MAP + '[metadata]\nbor = "25.7 mm"\n'})
# each file kind recognises the others
case("config-is-a-requirement-file", "check req.toml -r req.toml -q", "this is a requirement file, not a plant configuration")
case("req-is-a-plant", "check plant.toml -r plant.toml -q", "this is a plant configuration, not a requirement file")
case("settings-is-a-requirement-file", "validate plant.toml rec.csv --settings req.toml",
     "this is a requirement file, not a validation settings file")
case("sweep-is-a-requirement-file", "sweep req.toml --out new-out", "this is a requirement file, not a sweep file")
case("sweep-base-is-a-requirement-file", "sweep bad-sweep.toml --out new-out", "this is a requirement file, not a plant",
     {"bad-sweep.toml": sweep('base = "plant.toml"', 'base = "req.toml"')})
case("sweep-unknown-key-did-you-mean", "sweep bad-sweep.toml --out new-out", "did you mean 'method'",
     {"bad-sweep.toml": sweep('method = "grid"', 'methd = "grid"')})
case("sweep-yield-best-before-sweep", "sweep bad-sweep.toml --out new-out --yield best", "no sweep results",
     {"bad-sweep.toml": SWEEP + '[uncertain."controller.kp"]\ndistribution = "normal"\nstd = "1 %"\n'})
case("config-bom-and-unknown-key", "check bad.toml -r req.toml -q", "moving_mas",
     {"bad.toml": BOM + plant('moving_mass =', 'moving_mas = { value = "1 kg", source = "paper" }\nmoving_mass =')})
case("config-command-limit-below-saturation", "check bad.toml -r req.toml -q", "command_limit",
     {"bad.toml": plant('command_limit = { value = "10 V"', 'command_limit = { value = "3 V"')})
case("sim-sine-beyond-stroke", f"{SIM} --sine 100mm,1Hz", "outside the stroke")
case("sim-sine-above-nyquist", f"{SIM} --sine 1mm,600Hz", "Nyquist")
case("req-step-size-zero", CHECKR, "zero", {"bad-req.toml": req('size = "5 %stroke"', 'size = "0 %stroke"')})
case("req-load-beyond-cylinder", CHECKR, "more than twice", {"bad-req.toml": req('load = "none"', 'load = "1 MN"')})
case("gate-allow-unknown-id", "gate plant.toml --baseline plant.toml -r req.toml --allow-not-evaluated TCC -q",
     "did you mean 'TC'")
case("diag-effects-empty", ["diagnose", "plant.toml", "rec.csv", "--effects", ""], "--effects ''")
# an output that is one of the inputs, or of the wrong kind
case("out-reproduce-calibrate-is-the-plant", "reproduce plant.toml --calibrate plant.toml", "is an input of this run")
case("out-reproduce-calibrate-json", "reproduce plant.toml --calibrate out/cal.json", ".toml")
case("out-gate-json-is-baseline", "gate plant.toml --baseline out/good.json --json out/good.json", "is an input of this run")
case("out-validate-json-is-recording-map", "validate plant.toml rec.csv --column-map map.toml --json map.toml", ".json")
# internal errors before
case("linear-tiny-moving-mass", "linear bad.toml", "no mode from the valve command",
     {"bad.toml": plant('"30 kg"', '"1e-9 kg"')})
case("check-epoch-year-10000", "check plant.toml -r req.toml --json out/r.json -q", "9999-12-31",
     env={"SOURCE_DATE_EPOCH": "253402300800"})
case("sweep-scheduler-no-port", ["sweep", "bad-sweep.toml", "--scheduler", "127.0.0.1", "--out", "new-out"], "--scheduler",
     {"bad-sweep.toml": SWEEP})
case("sweep-scheduler-refused", ["sweep", "bad-sweep.toml", "--scheduler", "tcp://127.0.0.1:1", "--out", "new-out"],
     "cannot reach the Dask scheduler at 127.0.0.1:1 (Connection refused)", {"bad-sweep.toml": SWEEP})
case("report-text-where-value-belongs", "report bad.json --report out/r.html", "where a number",
     {"bad.json": lambda ws: W.damaged_results(ws / "bad.json")})
case("bench-seed-negative", "diagnose-benchmark --seed -1 --cases 1", "--seed")
case("bare-govcheck-no-command", [], "no COMMAND given")

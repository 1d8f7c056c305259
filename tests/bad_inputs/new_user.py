"""Bad inputs a new user meets on the newer features: sizing, remedies, the hardware catalogue, uncertainty
ranges, joint diagnosis, instrument declarations, schedulers, document control and conflicting requirement sets.

Each case is a mistake someone makes on a first afternoon with the README open: a duty written in
newtons under a kN unit, the dashboard address given as the scheduler, a transducer's range copied
from the wrong data sheet, a copy of the same recording passed twice under two names, a document
number given to a run that makes no report. The rules are those of ``cases.py``: exit code 2, one
message naming the mistake (the fragment), no traceback, nothing written or changed.
"""

from __future__ import annotations

from tests.bad_inputs import workspace as W
from tests.bad_inputs.cases import Case

CASES: list[Case] = []
CLASSES = ("size", "remedies", "catalogue", "range", "joint", "sidecar", "scheduler", "doc", "conflict")


def case(id, argv, fragment, files=None, code=2, env=None):
    assert id.split("-")[0] in CLASSES + ("older",), id
    CASES.append(Case(id, files or {}, argv.split() if isinstance(argv, str) else argv, fragment, code, env or {}))


# ------------------------------------------------------------------------------------- sizing: the duty and `size`
DUTY = '''schema = "govcheck-duty/1"
name = "my-gate"
template = "plant.toml"
stroke = "160 mm"
supply_pressure = "8 bar abs"
opening_time = "5 s"
closing_time = "5 s"
setup_force = "5.7 kN"
[load.curve]
position = { values = [0, 50, 100], unit = "percent" }
force = { values = [2.0, 9.0, 12.0], unit = "kN" }
'''


def duty(old, new):
    assert old in DUTY, old
    return DUTY.replace(old, new, 1)


SIZE = "size req.toml --duty duty.toml --out out/sized.toml -q"
for cid, text, frag in [
    # the forces copied in newtons under the kN unit: 12 000 kN
    ("size-duty-newtons-under-kn", duty("[2.0, 9.0, 12.0]", "[2000, 9000, 12000]"), "load.curve.force: 1.2e+04 kN is more than"),
    # "1 bar" of a gauge reading written as abs: below atmosphere
    ("size-duty-supply-below-atmosphere", duty('"8 bar abs"', '"1 bar abs"'), "supply_pressure: 1 bar abs is not above atmosphere"),
    ("size-duty-supply-30-bar", duty('"8 bar abs"', '"30 bar abs"'), "above the 16 bar gauge"),
    ("size-duty-setup-force-above-curve", duty('"5.7 kN"', '"57 kN"'), "setup_force: 57 kN is outside the duty's own forces"),
    ("size-duty-all-forces-zero", duty("[2.0, 9.0, 12.0]", "[0, 0, 0]"), "every force is zero"),
]:
    case(cid, SIZE, frag, {"duty.toml": text})
case("size-out-over-the-template", "size req.toml --duty duty.toml --out plant.toml -q",
     "--out plant.toml: is an input of this run (the template of duty.toml)", {"duty.toml": DUTY})
case("size-out-over-the-duty", "size req.toml --duty duty.toml --out duty.toml -q", "--out duty.toml: is an input of this run",
     {"duty.toml": DUTY})
case("size-no-check-json", "size req.toml --duty duty.toml --no-check --json out/s.json", "--json does nothing with --no-check",
     {"duty.toml": DUTY})
case("size-no-check-remedies", "size req.toml --duty duty.toml --no-check --remedies", "--remedies does nothing with --no-check",
     {"duty.toml": DUTY})
case("size-duty-is-the-plant", "size req.toml --duty plant.toml -q", "this is a plant configuration, not a duty file")
case("size-requirements-is-the-duty", "size duty.toml --duty duty.toml -q", "this is a duty file, not a requirement file",
     {"duty.toml": DUTY})
case("size-out-json-suffix", "size req.toml --duty duty.toml --out out/sized.json -q", "--out out/sized.json: expected a file ending in .toml",
     {"duty.toml": DUTY})

# ------------------------------------------------------------------------------------- remedies options
case("remedies-catalogue-alone", "check plant.toml -r req.toml --catalogue models/cat.toml -q", "--catalogue needs --remedies")
case("remedies-yield-units-alone", "check plant.toml -r req.toml --yield-units 20 -q", "--yield-units needs --remedies")
case("remedies-state-in-missing-folder", "check plant.toml -r req.toml --remedies --remedies-state runs/state -q",
     "--remedies-state runs/state: folder 'runs' does not exist")
case("remedies-state-is-a-file", "check plant.toml -r req.toml --remedies --remedies-state out/good.json -q",
     "--remedies-state out/good.json: is a file")
case("remedies-save-over-the-plant", "check plant.toml -r req.toml --remedies --save-remedy plant.toml -q",
     "--save-remedy plant.toml: is an input of this run")
case("remedies-catalogue-is-the-requirements", "check plant.toml -r req.toml --remedies --catalogue req.toml -q",
     "req.toml: this is a requirement file, not a hardware catalogue")

# ------------------------------------------------------------------------------------- the hardware catalogue
CAT = '''schema = "govcheck-hardware/1"
[options.big-valve]
group = "servo_valve"
title = "a bigger valve"
cost = 2.0
valve_rating = "1400 NL/min"
'''
CHECK_CAT = "check plant.toml -r req.toml --remedies --catalogue cat.toml -q"
for cid, extra, frag in [
    ("catalogue-rod-thicker-than-bore", '[options.cyl]\ngroup = "cylinder_bore"\ntitle = "t"\ncost = 3\n'
                                        'sets = { "cylinder.piston_diameter" = "100 mm", "cylinder.rod_diameter" = "110 mm" }\n',
     "a 110 mm rod on a 100 mm bore"),
    ("catalogue-key-typo", '[options.huge]\ngroup = "servo_valve"\ntitle = "t"\ncost = 3\nvaluve_rating = "700 NL/min"\n',
     "valuve_rating"),
    ("catalogue-rating-1e9", '[options.huge]\ngroup = "servo_valve"\ntitle = "t"\ncost = 3\nvalve_rating = "1e9 NL/min"\n',
     "no pneumatic valve is rated above"),
    ("catalogue-rating-and-conductance-disagree",
     '[options.two]\ngroup = "servo_valve"\ntitle = "t"\ncost = 3\nvalve_rating = "700 NL/min"\n'
     'sets = { "valve.sonic_conductance" = "9 dm^3/(s*bar)" }\n', "describe two different valves"),
    ("catalogue-supply-below-atmosphere", '[options.low]\ngroup = "supply_pressure"\ntitle = "t"\ncost = 1\n'
                                          'sets = { "air.supply_pressure" = "0.6 bar abs" }\n', "is not above atmosphere"),
    ("catalogue-supply-without-abs", '[options.six]\ngroup = "supply_pressure"\ntitle = "t"\ncost = 1\n'
                                     'sets = { "air.supply_pressure" = "6 bar" }\n', "air.supply_pressure"),
    ("catalogue-group-typo", '[options.v]\ngroup = "servo-valve"\ntitle = "t"\ncost = 1\nvalve_rating = "700 NL/min"\n',
     "'servo-valve' is not one of"),
]:
    case(cid, CHECK_CAT, frag, {"cat.toml": CAT + extra})

# ------------------------------------------------------------------------------------- uncertainty ranges in the plant file
STATIC = 'static_force = { value = "420 N", source = "assumed", range = ["336 N", "504 N"]'


def plant_range(new_range: str, key_line: str = STATIC, old_range: str = 'range = ["336 N", "504 N"]') -> str:
    assert key_line in W.PLANT_A, key_line
    return W.PLANT_A.replace(key_line, key_line.replace(old_range, new_range), 1)


RANGE = "check bad.toml -r req.toml -q --uncertainty 8"
for cid, text, frag in [
    ("range-written-high-first", plant_range('range = ["504 N", "336 N"]'), "low 504 is above high 336 N"),
    ("range-not-around-the-value", plant_range('range = ["500 N", "600 N"]'), "must contain the value 420"),
    ("range-in-volts-for-a-force", plant_range('range = ["300 V", "500 V"]'), "friction.static_force.range"),
    ("range-with-bar-on-a-ratio",
     W.PLANT_A.replace('critical_pressure_ratio = { value = 0.528, source = "paper" }',
                       'critical_pressure_ratio = { value = 0.528, source = "paper", range = ["0.4 bar", "0.6 bar"], '
                       'range_note = "b scatters" }', 1),
     "this parameter is a pure number"),
    ("range-on-an-effect-parameter",
     W.PLANT_A + '\n[effects.valve_dynamics]\nnatural_frequency = { value = "60 Hz", range = ["40 Hz", "80 Hz"], '
                 'range_note = "no bench test" }\n', "ranges and derivation targets are read on base parameters only"),
]:
    case(cid, RANGE, frag, {"bad.toml": text})

# ------------------------------------------------------------------------------------- joint diagnosis of several recordings
OTHER = W.csv_text(W.recording_columns() | {"valve_command": 0.02 * W.recording_columns()["valve_command"]})
case("joint-copy-under-another-name", "diagnose plant.toml rec.csv copy.csv -q", "copy.csv: the same bytes as rec.csv",
     {"copy.csv": W.csv_text(), "copy.toml": W.SIDECAR})
case("joint-sidecars-name-two-plants", "diagnose rec.csv other.csv -q", "its sidecar names plant 'plant-b'",
     {"other.csv": OTHER, "other.toml": W.SIDECAR.replace('"plant-a"', '"plant-b"')})
case("joint-two-plants-even-with-config", "diagnose plant.toml rec.csv other.csv -q", "its sidecar names plant 'plant-b'",
     {"other.csv": OTHER, "other.toml": W.SIDECAR.replace('"plant-a"', '"plant-b"')})
case("joint-asks-for-a-pdf", "diagnose plant.toml rec.csv other.csv --pdf out/j.pdf", "--pdf: not available for a joint diagnosis",
     {"other.csv": OTHER, "other.toml": W.SIDECAR})
case("joint-document-number", "diagnose plant.toml rec.csv other.csv --document-number GC-1 --json out/j.json",
     "--document-number", {"other.csv": OTHER, "other.toml": W.SIDECAR})

# ------------------------------------------------------------------------------------- what a sidecar declares about its instruments
VAL = "validate plant.toml s.csv --json out/v.json"
for cid, extra, frag in [
    ("sidecar-logger-rate-of-another-logger", '[logger]\nrate = "250 Hz"\n',
     "logger.rate = 250 Hz, and the time stamps are 1000 Hz apart"),
    ("sidecar-logger-rate-1-hz", '[logger]\nrate = 1.0\n', "logger.rate = 1 Hz"),
    ("sidecar-position-range-of-a-50mm-transducer", '[channels.position]\nrange = ["0 mm", "50 mm"]\n',
     "channels.position.range = 0 .. 50 mm"),
    ("sidecar-pressure-range-too-low", '[channels.pressure_a]\nrange = ["0 bar", "2 bar"]\n',
     "channels.pressure_a.range = 0 .. 2 bar (gauge or absolute)"),
    ("sidecar-delay-in-seconds", '[channels.pressure_b]\ndelay = "5 s"\n', "channels.pressure_b.delay = 5 s is as long as"),
]:
    case(cid, VAL, frag, {"s.csv": W.csv_text(), "s.toml": W.SIDECAR + extra})

# ------------------------------------------------------------------------------------- --scheduler addresses
SWEEP = '''schema = "govcheck-sweep/1"
name = "tiny"
title = "t"
base = "plant.toml"
requirements = "req.toml"
[search]
method = "grid"
[adjust."controller.kp"]
values = ["280 V/m", "300 V/m"]
'''
for cid, address, frag in [
    ("scheduler-dashboard-url", "http://127.0.0.1:8787/status", "unknown address scheme"),
    ("scheduler-port-too-large", "tcp://127.0.0.1:99999", "port '99999' is not a TCP port"),
    ("scheduler-inproc", "inproc://my-cluster", "inproc:// address names a scheduler inside the same Python process"),
    ("scheduler-no-host", "tcp://:8786", "no host"),
    ("scheduler-local-workers-word", "local:two", "expected local:N with N >= 1"),
]:
    case(cid, ["sweep", "s.toml", "--scheduler", address, "--out", "new-out", "-q"], frag, {"s.toml": SWEEP})
case("scheduler-unreachable-before-work", ["check", "plant.toml", "-r", "req.toml", "--remedies", "--scheduler",
                                           "tcp://127.0.0.1:1", "-q"], "cannot reach the Dask scheduler at 127.0.0.1:1")

# ------------------------------------------------------------------------------------- document control without a document
case("doc-number-without-report", "check plant.toml -r req.toml --json out/r.json --document-number GC-7 -q",
     "--document-number GC-7: is printed on the report, and no report is asked for")
case("doc-accept-revision-without-report", "accept site -r req.toml --revision C --json out/s.json -q",
     "--revision C: is printed on the report")
case("doc-revision-without-report", "diagnose plant.toml rec.csv --revision B --json out/d.json",
     "--revision B: is printed on the report")

# ------------------------------------------------------------------------------------- requirement sets that contradict themselves
CONFLICT = W.REQUIREMENTS + '''
[requirements.TC-FAST]
title = "Time constant, fast governor"
clause = "test"
metric = "time_constant"
comparator = "within"
limit = ["0.30 s", "0.40 s"]
procedures = ["steps-5"]
operating_points = ["mid"]
severity = "mandatory"
'''
case("conflict-disjoint-windows-check", "check plant.toml -r conflict.toml -q", "no value lies in both",
     {"conflict.toml": CONFLICT})
case("conflict-size", "size conflict.toml --duty duty.toml -q", "the requirement set contradicts itself",
     {"conflict.toml": CONFLICT, "duty.toml": DUTY})
case("conflict-sweep", "sweep s.toml --out new-out -q", "the requirement set contradicts itself",
     {"conflict.toml": CONFLICT, "s.toml": SWEEP.replace('requirements = "req.toml"', 'requirements = "conflict.toml"')})
case("conflict-gate", "gate plant.toml --baseline plant.toml -r conflict.toml -q", "the requirement set contradicts itself",
     {"conflict.toml": CONFLICT})

# ------------------------------------------------------------------------------------- options that do nothing where given
case("older-linear-stroke-load-alone", "linear plant.toml --stroke-load banana", "--stroke-load banana: the load of the governor's")
case("older-linear-rating-alone", "linear plant.toml --rating 50MVA", "--rating 50MVA: a basis of the governor export")
case("older-linear-rating-bare-number", "linear plant.toml --governor --rating 50", "give the unit, e.g. '50 MVA'")
case("older-sweep-samples-on-a-grid", "sweep s.toml --samples 10 --out new-out -q", "searches a grid",
     {"s.toml": SWEEP})
case("older-sweep-units-without-yield", "sweep s.toml --units 100 --out new-out -q", "without --yield no yield is run",
     {"s.toml": SWEEP})
case("older-reproduce-jobs-without-calibrate", "reproduce plant.toml -j 2", "only the --calibrate search runs in parallel")
case("older-char-valve-laws-empty", ["characterise", "valve", "rec.csv", "--volume", "1 L", "--laws", ""],
     "--laws '': no flow law named")
case("older-sim-cfg-over-users-dat", "simulate plant.toml -o mine.cfg", "its COMTRADE data file mine.dat exists and was not written",
     {"mine.dat": "1,0,5\n"})
case("older-no-sidecar-names-no-file", "validate plant.toml bare.csv", "bare.csv: no sidecar (bare.toml, beside the recording, does not exist)",
     {"bare.csv": W.csv_text()})
case("older-transducer-unplugged", "validate plant.toml flat.csv", "is its transducer unplugged",
     {"flat.csv": W.csv_text(W.recording_columns() | {"position": 0.0 * W.recording_columns()["position"]}),
      "flat.toml": W.SIDECAR})
case("older-map-skips-every-line", "validate plant.toml m.txt --column-map skip.toml --mode plant_only",
     "skip_rows = 500 skips every line", {"m.txt": "t_ms,x_mm,u_V,pA_bar\n" + "".join(f"{i},80,0.01,4.9\n" for i in range(200)),
                                          "skip.toml": "skip_rows = 500\n" + W.COLUMN_MAP})


def damaged(path_keys, value="lots"):
    """The shipped results fixture with text at ``path_keys`` (a hand edit of a number)."""
    def write(ws):
        import json

        data = json.loads((W.REPO / "tests" / "data" / "results_fixture.json").read_text(encoding="utf-8"))
        node = data
        for k in path_keys[:-1]:
            node = node[k]
        node[path_keys[-1]] = value
        (ws / "bad.json").write_text(json.dumps(data), encoding="utf-8")
    return write


for cid, keys in [
    ("older-report-text-in-the-linear-map", ("linear", "map", "window", 0)),
    ("older-report-text-in-the-governor-tg", ("linear", "governor", "parameters", "Tg")),
    ("older-report-text-in-a-crosscheck", ("linear", "crosscheck", 0, "tau_linear")),
    ("older-report-text-in-a-pole", ("linear", "analysis", "poles", "closed_loop", 0, 0)),
]:
    case(cid, "report bad.json --report out/r.html", "where a number (or null) belongs", {"bad.json": damaged(keys)})



def corrupted_gz(ws):
    """A compressed results file damaged inside its deflate stream (a bad copy): the header is intact."""
    import gzip

    data = gzip.compress((W.REPO / "tests" / "data" / "results_fixture.json").read_bytes())
    (ws / "best.json.gz").write_bytes(data[:12] + bytes(b ^ 0x55 for b in data[12:40]) + data[40:])


case("older-report-corrupted-gz", "report best.json.gz --report out/r.html", "best.json.gz: not a JSON results file",
     {"best.json.gz": corrupted_gz})
case("older-gate-corrupted-gz", "gate best.json.gz --baseline best.json.gz", "best.json.gz: not a JSON results file",
     {"best.json.gz": corrupted_gz})

# options that shape something the run does not do
case("older-reproducible-writing-nothing", "validate plant.toml rec.csv --reproducible -q",
     "--reproducible: makes the files a run writes byte-identical, and this run writes none")
case("older-sim-bad-epoch", "simulate plant.toml -o out/n.csv", "SOURCE_DATE_EPOCH='last week': expected a whole number",
     env={"SOURCE_DATE_EPOCH": "last week"})
case("older-accept-jobs-without-prediction", "accept site -r req.toml --no-prediction -j 2 --json out/s.json -q",
     "--jobs 2: the prediction's replays run in parallel, and --no-prediction runs none")
case("older-validate-noise-on-plant-only", "validate plant.toml rec.csv --mode plant_only --noise none -q",
     "--noise none: the position noise of the closed-loop replay")
case("older-sim-seed-without-noise", "simulate plant.toml -o out/n.csv --seed 3", "--seed 3: seeds the sensor noise")
case("older-check-appendix-without-report", "check plant.toml -r req.toml --appendix full --json out/r.json -q",
     "--appendix full: shapes the report")
case("older-gate-requirements-between-results", "gate out/a.json --baseline out/b.json -r req.toml",
     "--requirements: both sides are results files", {"out/a.json": '{"schema": "x"}', "out/b.json": '{"schema": "x"}'})
case("older-bench-cases-with-practice", "diagnose-benchmark --practice out --cases 5", "--cases: shapes the generated cases")
case("older-diag-friction-bore-on-a-servo-run", "diagnose plant.toml rec.csv --friction-bore 25mm",
     "--friction-bore 25mm: the bore of a friction-bench run")

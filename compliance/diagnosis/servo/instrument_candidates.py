"""Instrumentation findings: what the logger or a transducer did to a recording, as candidates of their own kind.

A field recording can miss the model because of its instruments, not the plant: a channel group
logged a few ms late on a second acquisition module, a pressure transducer with a 1-2 % gain
error, a logger that delays every channel (an undeclared anti-alias filter: a first-order filter
at f_c delays slow signals by 1/(2 pi f_c)). None of these changes what the controller saw, so
none is plant physics; each is fitted like an effect (``servo.fit.FitContext`` puts it on the replayed
channels through ``validation.logger_model`` and takes it back from the states the
re-synchronisations read, ``LoggerModel.true_states``) and competes under the same
selection rule (``servo.selection.beats``): a plant-physics claim must beat the best of them, and when an
instrumentation finding explains the recording the verdict is ``instrumentation``: check the
instruments, the plant is not shown to be wrong.

Our own choices (not from a standard): the candidate set below and its bounds (±20 ms of channel
offset, ±10 % of gain; a logger delay up to 20 ms, i.e. a first-order filter down to 8 Hz).
"""

from __future__ import annotations

from dataclasses import replace

from compliance.model.parameters import ParamHandle
from compliance.diagnosis.servo.candidates import Candidate
from compliance.diagnosis.verdicts.candidate_set import INSTRUMENT_PREFIX as PREFIX
from compliance.validation.logger_model import FILTERED, PRESSURES, LoggerModel
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict

KIND = "instrument"
MAX_OFFSET = 0.02  # s; largest channel time offset fitted
MAX_GAIN_ERROR = 0.10  # relative; largest transducer gain error fitted
OFFSET_GRID = (-0.004, 0.0, 0.004)  # s; starting points of an offset fit
MEANING = {
    "pressure_time_offset": "the pressure channels are logged {v} later than position and command (a time offset "
                            "between channel groups, e.g. a second acquisition module)",
    "position_time_offset": "the position channel is logged {v} later than the valve command (a logging delay the "
                            "controller did not see)",
    "logger_delay": "every logged channel trails the controller's set-point by {v} (a logger lag: an undeclared "
                    "anti-alias filter or transmission delay)",
    "pressure_gain": "a pressure transducer's gain is off: {v}",
}


def _offset(name: str, low: float = -MAX_OFFSET) -> Candidate:
    fp = ParamHandle(f"{PREFIX}{name}.delay", "s", low, MAX_OFFSET, kind=KIND, nominal=0.0)
    grid = tuple({"delay": d} for d in OFFSET_GRID if d >= low)
    return Candidate(PREFIX + name, (fp,), grid)


def instrument_candidates(signals, closed_loop: bool) -> list[Candidate]:
    """The instrumentation candidates a recording's compared ``signals`` can show."""
    pressures = [s for s in PRESSURES if s in signals]
    out = []
    if pressures:
        out.append(_offset("pressure_time_offset"))
        gains = tuple(ParamHandle(f"{PREFIX}pressure_gain.{p}", "", 1.0 - MAX_GAIN_ERROR, 1.0 + MAX_GAIN_ERROR, kind=KIND, nominal=1.0)
                      for p in pressures)
        out.append(Candidate(PREFIX + "pressure_gain", gains, ({},)))
    if closed_loop and "position" in signals and "valve_command" in signals:
        out.append(_offset("position_time_offset"))
        out.append(_offset("logger_delay", low=0.0))
    return out


def instrumented(setup, params, values):
    """The replay set-up with the instrumentation parameters among ``params`` on its logger model."""
    delay, gain = {}, {}
    for fp, v in zip(params, values):
        if fp.kind != KIND:
            continue
        what, name = fp.key[len(PREFIX):].split(".", 1)
        if what == "pressure_time_offset":
            delay.update({p: v for p in PRESSURES})
        elif what == "position_time_offset":
            delay["position"] = v
        elif what == "logger_delay":
            delay.update({s: v for s in FILTERED})
        elif what == "pressure_gain":
            gain[name] = v
    if not delay and not gain:
        return setup
    ts = float(setup.time[1] - setup.time[0]) if setup.time.size > 1 else 1.0
    states = LoggerModel(delay=delay, gain=gain).true_states(setup.states, ts)  # the re-synchronisations read the plant
    return replace(setup, logger=(setup.logger or LoggerModel()).with_extra(delay=delay, gain=gain), states=states)


def finding_words(fit) -> str:
    """The instrumentation finding of a fit (an instrumentation candidate, or a plant explanation with one on top) in words."""
    from compliance.presentation.numbers import fmt_si

    pairs = [(fp, v) for fp, v in zip(fit.params, fit.values) if fp.kind == KIND]
    if not pairs:
        return ""
    what = pairs[0][0].key[len(PREFIX):].split(".", 1)[0]
    if what == "pressure_gain":
        v = ", ".join(f"{fp.name} x {val:.4f} ({100 * (val - 1):+.2f} % on gauge pressure)" for fp, val in pairs)
    else:
        v = fmt_si(pairs[0][1], "s")
    return MEANING.get(what, what).format(v=v)


def instrument_verdict(scores: dict, n: int, decided: tuple, names) -> tuple:
    """The verdict once the instrumentation candidates are heard: (verdict, winner, reason).

    ``decided`` is the plant-side (verdict, winner, reason). The best instrumentation finding
    takes over when it beats the nominal model (``servo.selection.beats``, the rule every explanation
    meets) and explains enough, and the plant-side winner (an effect, a set, the recalibration)
    does not beat it in turn; a ``no_mismatch`` stands.
    """
    from compliance.diagnosis.servo.selection import EXPLAINED_ENOUGH, beats

    verdict_name, winner, reason = decided
    names = [k for k in names if k in scores]
    if verdict_name == DiagnosisVerdict.NO_MISMATCH or not names:
        return decided
    best = min(names, key=lambda k: scores[k].bic)
    if not beats(scores, best, "nominal", n) or scores[best].explained < EXPLAINED_ENOUGH:
        return decided
    if winner is not None and winner in scores and beats(scores, winner, best, n):
        return decided
    why = (f"{best[len(PREFIX):].replace('_', ' ')} explains {100 * scores[best].explained:.0f} % of the excess residual"
           + (f" and {winner} does not beat it" if winner else "") + ": check the instrumentation, not the plant")
    return DiagnosisVerdict.INSTRUMENTATION, best, why


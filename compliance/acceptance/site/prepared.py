"""A site's recordings made ready to judge: the test each holds (stated or recognised), its instruments, its problems.

For every recording: the sidecar's test (``site.stated``), checked against what the trace shows
(``site.recognise``) or, when the sidecar does not say, taken from the trace (and said); the
recording checked against the plant (``recordings.against_plant``); its instruments measured and
its position conditioned (``measure.conditioning``). A recording that cannot be judged as run (its
sidecar and its trace disagree, the trace shows no known test) keeps its reason: its cases are
NOT EVALUATED, the others are judged.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.acceptance.measure.conditioning import Conditioned, condition
from compliance.acceptance.site.folder import SiteRecording
from compliance.acceptance.site.recognise import disagreement, recognise
from compliance.acceptance.site.stated import SiteTest, site_test
from compliance.recordings.against_plant import check_against_plant

__all__ = ["PreparedTest", "prepare"]


@dataclass
class PreparedTest:
    """A recording with its test as run, its conditioned trace and, if it cannot be judged, why."""

    recording: SiteRecording
    test: SiteTest
    cond: Conditioned
    problem: str | None = None

    @property
    def name(self) -> str:
        """The recording's name."""
        return self.recording.name


def prepare(rec: SiteRecording, cfg) -> PreparedTest:
    """The test a recording holds, ready to measure (see the module docstring).

    Raises
    ------
    InputError
        A sidecar value of the wrong type, a recording impossible for the plant (outside the stroke,
        a pressure above the supply), too few samples.
    """
    where = str(rec.path)
    check_against_plant(cfg, rec.frame, rec.meta, rec.path)
    run = site_test(rec.meta, where)
    cond = condition(rec.frame, rec.meta, where)
    seen, how, settings = recognise(cond, cfg.p("cylinder.stroke"), cfg.p("valve.centre_voltage"))
    if run.kind is None:
        if seen is None:
            return PreparedTest(rec, run, cond, f"the sidecar does not say which test this is and the trace shows none "
                                                f"of the standard tests ({how})")
        return PreparedTest(rec, run.recognised(seen, how, settings, None), cond)
    why = disagreement(run.kind, seen, how)
    return PreparedTest(rec, run, cond, why)

"""``compliance.check``: a plant judged against a requirement set in one library call that returns a typed result.

As pvlib's ``ModelChain`` runs public steps and leaves a result object, :func:`check` runs these
steps, each a public function a caller may run alone, and returns a frozen
:class:`~compliance.results.CheckResult` that the terminal, the results files, the gate and the
report read:

1. :func:`vet` the requirement set: loosened limits and limits that cannot hold together, once,
   before any simulation (``requirements.vetting``);
2. :func:`campaign`: plan and execute every procedure x operating point (``campaign.run``);
3. :func:`judgement`: every requirement x procedure x operating point against its limit
   (``campaign.judge``);
4. :func:`bands`: each verdict's range over the plant file's declared parameter ranges, by local
   sensitivities or a Monte Carlo (``campaign.uncertainty``, ``sweep.tolerance.uncertainty_mc``);
5. :func:`evidence`: the model's agreement with the measurements its plant file names, and the
   verdicts they contradict (``model_evidence``);
6. :func:`linear_analysis`: the linear analysis at every operating point (``linear.operating_points``);
7. :func:`stability`: the loop's stability margins against govcheck's criterion at every operating
   point, reusing the linear analyses when made (``linear.stability``);
8. :func:`remedy_search`: what would make it pass (``sweep.check_remedies``).
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.errors import InputError
from compliance.results.check_result import CheckResult

__all__ = ["Check", "bands", "campaign", "check", "evidence", "judgement", "linear_analysis", "remedy_search", "stability",
           "vet"]


def _plant(plant):
    from compliance.model.config import PlantConfig, load_plant

    return plant if isinstance(plant, PlantConfig) else load_plant(plant)


def _requirements(requirements):
    from compliance.requirements.requirement_set import RequirementSet
    from compliance.requirements.loading import load_requirements

    return requirements if isinstance(requirements, RequirementSet) else load_requirements(requirements)


def check_uncertainty(uncertainty, cfg=None) -> None:
    """``uncertainty``: "local", None/0 (point values) or N >= 2 plants of a Monte Carlo over declared ranges.

    Raises
    ------
    InputError
        One plant (or fewer), an unknown method, or (given the plant) N plants but no declared range.
    """
    if uncertainty in (None, "local", 0):
        return
    if isinstance(uncertainty, bool) or not isinstance(uncertainty, int):
        raise InputError(f"uncertainty={uncertainty!r}: expected 'local', 0 (point values) or a number of plants "
                         "(>= 2)")
    if uncertainty < 2:
        raise InputError(f"--uncertainty {uncertainty}: expected at least 2 plants (or 0 for point values)")
    if cfg is not None:
        from compliance.campaign.uncertainty import ranged_parameters

        if not ranged_parameters(cfg):
            raise InputError(f"{cfg.path or cfg.name}: --uncertainty {uncertainty}: the plant file gives no parameter "
                             "a range (range = [low, high] with range_note, docs/requirements.md 'Uncertainty')")


def check_remedies(remedies) -> None:
    """A remedies sweep file is read before any simulation (a bad one is ``InputError``)."""
    if remedies and remedies not in (True, "default"):
        from compliance.sweep.candidates.spec import load_sweep

        load_sweep(remedies)


# --------------------------------------------------------------------------- the steps
def vet(cfg, reqset, allow_conflicts: bool = False):
    """Step 1: the requirement set's loosening notes and findings (``InputError`` on a mandatory conflict)."""
    from compliance.requirements.vetting import vet as vet_set

    return vet_set(reqset, cfg.p("cylinder.stroke"), allow_conflicts)


def campaign(cfg, reqset, *, jobs: int | None = None, scheduler: str | None = None, progress: bool = False):
    """Step 2: every run the set needs, executed (``campaign.run.CampaignRuns``)."""
    from compliance.campaign.run import execute_runs

    return execute_runs(cfg, reqset, workers=jobs, progress=progress, scheduler=scheduler)


def judgement(cfg, reqset, runs, vetting) -> tuple[list[dict], list[str]]:
    """Step 3: the verdict entries (one per requirement, its rows) and the summary's notes."""
    from compliance.campaign.judge import judge

    return judge(cfg, reqset, list(runs.jobs), list(runs.outcomes), vetting.loosened)


def bands(cfg, reqset, runs, entries: list[dict], uncertainty="local", *, jobs=None, progress=False) -> dict | None:
    """Step 4: bands on the verdicts (entries updated); the ``uncertainty`` section, or None for point values."""
    from compliance.campaign.uncertainty import local_bands, ranged_parameters

    if not uncertainty or not ranged_parameters(cfg):
        return None
    if uncertainty == "local":
        return local_bands(cfg, reqset, list(runs.jobs), entries, workers=jobs, progress=progress)
    from compliance.sweep.tolerance.uncertainty_mc import monte_carlo_bands

    return monte_carlo_bands(cfg, reqset, entries, uncertainty, workers=jobs, progress=progress)


def evidence(cfg, result: CheckResult):
    """Step 5: the model's evidence (``results.evidence.ModelEvidence``) on the result's final verdicts."""
    from compliance.model_evidence import model_evidence

    return model_evidence(cfg, result)


def linear_analysis(cfg, reqset, *, jobs: int | None = None) -> dict:
    """Step 6: the linear analysis at every operating point, the map, the cross-check and HYGOV."""
    from compliance.linear.operating_points import linear_for_campaign

    return linear_for_campaign(cfg, reqset, workers=jobs)


def stability(cfg, reqset, linear: dict | None = None, *, jobs: int | None = None):
    """Step 7: the loop's margins at every operating point against govcheck's criterion
    (``results.evidence.StabilitySection``); ``linear``'s analyses are reused when given."""
    from compliance.linear.stability import stability_margins
    from compliance.results.evidence import StabilitySection

    section = stability_margins(cfg, reqset, analyses=(linear or {}).get("analyses"), workers=jobs)
    return StabilitySection.from_dict(section, "results.stability")


def remedy_search(cfg, reqset, space="default", *, jobs=None, scheduler=None, progress=False, **options) -> dict:
    """Step 8: what would make it pass over ``space`` ("default" on-site settings, or a sweep file)."""
    from compliance.sweep.check_remedies import remedies_for_check

    options.setdefault("scheduler", scheduler)
    return remedies_for_check(cfg, reqset, space, workers=jobs, progress=progress, **options)


# --------------------------------------------------------------------------- the call
@dataclass(frozen=True)
class Check:
    """A check ready to run: the plant, the vetted requirement set and what to add (every input already checked).

    ``Check.of(...)`` loads and vets everything a check needs, so a bad input is an ``InputError``
    before any simulation; :meth:`run` then runs the steps. :func:`check` does both.
    """

    cfg: object  # PlantConfig
    reqset: object  # RequirementSet
    vetting: object  # requirements.vetting.Vetting
    linear: bool = False
    remedies: str | None = None  # None, "default" or a sweep file
    uncertainty: object = "local"

    @classmethod
    def of(cls, plant, requirements, *, linear: bool = False, remedies=None, uncertainty="local",
           allow_conflicts: bool = False) -> "Check":
        """Load and vet the inputs of a check (see :func:`check`); raises ``InputError`` before any simulation."""
        check_uncertainty(uncertainty)
        check_remedies(remedies)
        cfg, reqset = _plant(plant), _requirements(requirements)
        check_uncertainty(uncertainty, cfg)
        from compliance.model_evidence import check_sources

        check_sources(cfg)  # a [model_evidence] source govcheck cannot compare
        space = None if not remedies else "default" if remedies is True else remedies
        return cls(cfg, reqset, vet(cfg, reqset, allow_conflicts), bool(linear), space, uncertainty)

    def run(self, *, jobs: int | None = None, scheduler: str | None = None, progress: bool = False,
            command_line: str | None = None, remedy_options: dict | None = None, on_stage=None) -> CheckResult:
        """Run the steps (see the module docstring) and return the result."""
        from compliance.campaign.run import assemble

        cfg, reqset = self.cfg, self.reqset
        runs = campaign(cfg, reqset, jobs=jobs, scheduler=scheduler, progress=progress)
        entries, notes = judgement(cfg, reqset, runs, self.vetting)
        section = bands(cfg, reqset, runs, entries, self.uncertainty, jobs=jobs, progress=progress)
        result = CheckResult.of(assemble(cfg, reqset, runs, entries, notes, self.vetting, section, command_line))
        _stage(on_stage, "campaign")
        result = result.with_(model_evidence=evidence(cfg, result))
        _stage(on_stage, "model evidence")
        lin = linear_analysis(cfg, reqset, jobs=jobs) if self.linear else None
        result = result.with_(linear=lin, stability=stability(cfg, reqset, lin, jobs=jobs))
        _stage(on_stage, "linear analysis" if self.linear else "stability")
        if self.remedies:
            options = {"scheduler": scheduler, **(remedy_options or {})}  # the search's own scheduler, if given, wins
            rem = remedy_search(cfg, reqset, self.remedies, jobs=jobs, progress=progress, **options)
            result = result.with_(remedies=rem)
            _stage(on_stage, "remedies")
        return result


def check(plant, requirements, *, linear: bool = False, remedies=None, uncertainty="local",
          scheduler: str | None = None, jobs: int | None = None, allow_conflicts: bool = False, progress: bool = False,
          command_line: str | None = None, remedy_options: dict | None = None, on_stage=None) -> CheckResult:
    """Judge ``plant`` against ``requirements``, with evidence, in one call.

    Parameters
    ----------
    plant : PlantConfig, path or shipped name
    requirements : RequirementSet, path or shipped name
    linear : bool
        Add the linear analysis (every operating point, the stroke x load map, the cross-check, HYGOV).
    remedies : None, "default" or path
        Search what would make it pass over the on-site settings ("default") or a sweep file's space.
    uncertainty : "local", int or None
        Bands by local sensitivities over the plant file's declared ranges ("local"), a Latin-hypercube
        Monte Carlo of N plants (N >= 2), or point values only (None or 0).
    scheduler : str, optional
        Run the parallel work on Dask (``local:N`` or ``tcp://host:port``) instead of the local pool.
    jobs : int, optional
        Local processes (default: the available cores; 1 = serial).
    allow_conflicts : bool
        Judge a set whose mandatory limits conflict (without it: ``InputError`` before any simulation).
    progress : bool
        Progress bars of the runs on stderr.
    command_line : str, optional
        Recorded in the result.
    remedy_options : dict, optional
        Further keywords of the remedies search (``catalogue``, ``yield_units``, ``store``, ``iterations``, ...).
    on_stage : callable, optional
        ``on_stage(name)`` as each stage ends ("campaign" with the bands, "model evidence", "linear analysis"
        with the stability margins or, without it, "stability", "remedies").

    Returns
    -------
    CheckResult

    Raises
    ------
    InputError
        Bad input, found before any simulation: a plant or requirement file, a loosened limit, a
        conflict, an uncertainty or remedies option; a load beyond the cylinders before the runs start.
    """
    prepared = Check.of(plant, requirements, linear=linear, remedies=remedies, uncertainty=uncertainty,
                        allow_conflicts=allow_conflicts)
    return prepared.run(jobs=jobs, scheduler=scheduler, progress=progress, command_line=command_line,
                        remedy_options=remedy_options, on_stage=on_stage)


def _stage(on_stage, name: str) -> None:
    if on_stage is not None:
        on_stage(name)

"""A search resumes: candidates judged before are read from the store, not judged again."""

from __future__ import annotations

from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from compliance.sweep.candidates.candidate_store import CandidateStore
from compliance.sweep.candidates.evaluate import make_context
from compliance.sweep.candidates.parameter_paths import describe
from compliance.sweep.candidates.runner import run_candidates

from tests.sweep.conftest import SMALL_TC


def test_store_resumes_without_judging_again(tmp_path):
    ctx = make_context(load_plant("plant-a"), load_requirements(SMALL_TC), {"controller.kp": describe("controller.kp", "t")})
    cands = [{"controller.kp": 280.0}, {"controller.kp": 400.0}]
    first, stats = run_candidates(ctx, cands, workers=1, progress=False, store=CandidateStore(tmp_path))
    assert stats is not None and stats.done >= 1
    with (tmp_path / "candidates.jsonl").open("a") as f:
        f.write('{"key": "cut short')  # an interrupted write is ignored
    again = CandidateStore(tmp_path)  # as a new process would read the same folder
    rows, stats = run_candidates(ctx, cands, workers=1, progress=False, store=again)
    assert stats is None and rows == first  # nothing judged: every row came from the store
    rows, stats = run_candidates(ctx, cands + [{"controller.kp": 350.0}], workers=1, progress=False, store=again)
    assert stats is not None and stats.done == 1 and rows[:2] == first

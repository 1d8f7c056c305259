"""What the measurements say about the model: its agreement with the plant paper's measured figures and with
the recordings a plant file names, and which verdicts rest on figures the measurements contradict."""

from compliance.model_evidence.gather import check_sources, model_evidence

__all__ = ["check_sources", "model_evidence"]

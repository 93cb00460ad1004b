"""Stage 5: planning. A cell -> candidates per spot (`candidates`, over `poses`), the configuration
graph and detour learner (`graph`, with `sequence` and `roadmap`), the tour timed junction by
junction (`tour_timing`, `junction`, `waiting`), checked (`pipeline`) -> a `PlanResult` (`results`)."""

from robomax_py.plan.checked_tour import verify_trajectory
from robomax_py.plan.pipeline import plan_cell
from robomax_py.plan.results import (
    METHODS,
    FailureReason,
    OrderChoice,
    PlanOptions,
    PlanResult,
    PlanStage,
    PlanStats,
    PlanStatus,
    Progress,
    SpotFailure,
    SpotPlan,
    Transition,
    TransitionKind,
    method_options,
    method_suffix,
    resolved_options,
)
from robomax_py.plan.tour_timing import weld_end

__all__ = [
    "METHODS", "FailureReason", "OrderChoice", "PlanOptions", "PlanResult", "PlanStage", "PlanStats", "PlanStatus",
    "Progress", "SpotFailure", "SpotPlan", "Transition", "TransitionKind",
    "method_options", "method_suffix", "plan_cell", "resolved_options", "verify_trajectory", "weld_end",
]

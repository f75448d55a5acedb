"""The summary of a run: what was found, the route, the simulated drives; as text for people
(``format_summary``) and as JSON (``summary.json`` in ``--out``, ``--json``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from f2n_drake.core.parsed import UNSURE_BELOW

LISTED = 12
"""Names one line of the summary shows; ``summary.json`` holds them all."""


def listed(names: list[str], limit: int = LISTED) -> str:
    """The first ``limit`` of ``names``, joined, and how many more there are."""
    shown = ", ".join(names[:limit])
    if len(names) <= limit:
        return shown
    return f"{shown} and {len(names) - limit} more (summary.json lists them)"


def natural_order(name: str) -> tuple[str, int]:
    """Sort key: ``living_2`` before ``living_10``."""
    stem, _, number = name.rpartition("_")
    return (stem, int(number)) if number.isdigit() else (name, -1)


@dataclass
class RunSummary:
    input: str
    perception: str
    scale_m_per_px: float
    scale_source: str
    rooms: dict[str, int]
    connectors: dict[str, int]
    robot: str
    start: str = ""
    goal: str = ""
    route: list[str] = field(default_factory=list)
    path_length_m: float = 0.0
    planning_precompute_ms: float = 0.0
    planning_query_ms: float = 0.0
    status: str = "ok"  # "ok", "no route" or "goal not reached"
    error: str = ""
    simulation: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    wall_time_s: float = 0.0
    unsure: dict[str, float] = field(default_factory=dict)
    unreachable: list[str] = field(default_factory=list)
    on_other_plans: list[str] = field(default_factory=list)  # of ``unreachable``: drawn apart


def simulation_summary(mode: str, result) -> dict:
    return {
        "correction": mode,
        "reached": bool(result.reached),
        "collided": bool(result.collided),
        "success": bool(result.success),
        "sim_time_s": round(float(result.time_s), 2),
        "final_error_m": round(float(result.final_error_m), 4),
        "mean_error_m": round(float(result.mean_error_m), 4),
        "max_error_m": round(float(result.max_error_m), 4),
        "min_clearance_m": round(float(result.min_clearance_m), 4),
        "realtime_factor": round(float(result.realtime_factor), 1),
        "person_collisions": int(getattr(result, "person_collisions", 0)),
        "replans": int(getattr(result, "replans", 0)),
        "ended": str(getattr(result, "message", "")),
    }


def building_note(building, options) -> str:
    """One line: what the simulated building has that the plan lacks."""
    parts = []
    if options.clutter_fraction:
        parts.append(
            f"{len(building.furniture)} boxes and {len(building.cylinders)} round pieces of "
            f"furniture (up to {options.clutter_fraction * 100:.0f} % of each room's floor)"
        )
    if options.people:
        parts.append(f"{len(building.people)} people walking")
    if options.closed_doors:
        closed = ", ".join(building.closed_doors) or "none could be"
        parts.append(f"closed doors: {closed}")
    if options.deviation_m:
        parts.append(f"walls displaced by up to {options.deviation_m * 100:.0f} cm")
    return "the simulated building differs from the plan (the robot knows only the plan): " + (
        "; ".join(parts)
    )


def add_localization_summary(summary: RunSummary, results: dict) -> None:
    """The global-localization figures of unknown-start runs, in each simulation record and as
    a note per mode."""
    for record, (mode, r) in zip(summary.simulation, results.items(), strict=True):
        record.update(
            converged=bool(r.converged),
            time_to_converge_s=round(float(r.time_to_converge_s), 2) if r.converged else None,
            converged_error_m=round(float(r.converged_error_m), 4) if r.converged else None,
            wrong_convergence=bool(r.wrong_convergence),
            collided_before_converged=bool(r.collided_before_converged),
        )
        if r.converged:
            summary.notes.append(
                f"unknown start ({mode}): localized on the plan after {r.time_to_converge_s:.1f} s"
                f", {r.converged_error_m * 100:.1f} cm from the true pose"
                + (" (a wrong convergence)" if r.wrong_convergence else "")
            )
        else:
            summary.notes.append(f"unknown start ({mode}): the robot never localized itself")


def format_summary(s: RunSummary) -> str:
    rooms = ", ".join(f"{n} {c}" for c, n in s.rooms.items())
    conns = ", ".join(f"{n} {c}" for c, n in s.connectors.items())
    lines = [
        f"plan        {s.input}  ({s.perception})",
        f"scale       {s.scale_m_per_px * 100:.2f} cm/px ({s.scale_source})",
        f"found       {rooms}; {conns}",
    ]
    if s.unsure:  # the least sure first
        ranked = sorted(s.unsure, key=lambda k: (s.unsure[k], natural_order(k)))
        unsure = listed([f"{k} {100 * s.unsure[k]:.0f} %" for k in ranked])
        lines.append(f"unsure      {unsure} (mean class probability < {100 * UNSURE_BELOW:.0f} %)")
    if s.route:
        lines += [
            f"route       {s.robot}: {' -> '.join(s.route)}",
            f"path        {s.path_length_m:.2f} m; planning {s.planning_precompute_ms:.1f} ms "
            f"precompute + {s.planning_query_ms:.2f} ms query",
        ]
    else:
        lines.append(f"route       {s.robot}: none ({s.error})")
    for sim in s.simulation:
        verdict = (
            "COLLIDED"
            if sim["collided"]
            else ("reached the goal" if sim["reached"] else "did NOT reach the goal")
        )
        lines.append(
            f"simulation  correction {sim['correction']:10s} {verdict} after "
            f"{sim['sim_time_s']:.1f} s simulated; position error final "
            f"{sim['final_error_m'] * 100:.1f} cm, mean {sim['mean_error_m'] * 100:.1f} cm; "
            f"{sim['realtime_factor']:.0f}x real time"
            + (
                f"; touched a person {sim['person_collisions']} times"
                if sim.get("person_collisions")
                else ""
            )
            + (f"; {sim['replans']} replans" if sim.get("replans") else "")
            + (
                f" ({sim['ended']})"
                if not sim["reached"] and sim.get("ended") and not sim["collided"]
                else ""
            )
        )
    lines += [f"note        {n}" for n in s.notes]
    if s.outputs:
        lines.append(f"wrote       {len(s.outputs)} files to {Path(s.outputs[0]).parent}")
    lines.append(f"wall time   {s.wall_time_s:.1f} s")
    return "\n".join(lines)

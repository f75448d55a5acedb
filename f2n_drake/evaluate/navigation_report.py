"""The report of ``python -m f2n_drake.evaluate navigation``: per-mode figures from the run
records (success, errors, collisions, person contacts, replans; global localization for unknown
starts), the per-task lines, and the printed tables."""

from __future__ import annotations

import numpy as np

from f2n_drake.world.options import WorldOptions


def summary(runs: list[dict]) -> dict:
    """Per-mode figures from run records; error figures over the runs that did not fail to run
    (None when none did), so one crashed run cannot turn them into NaN."""
    n = len(runs)
    ran = [r for r in runs if not r["error"]]

    def over_ran(reduce, key: str) -> float | None:
        return float(reduce([r[key] for r in ran])) if ran else None

    return {
        "success_rate": sum(r["success"] for r in runs) / n,
        "mean_error_m": over_ran(np.mean, "mean_error_m"),
        "max_error_m": over_ran(np.max, "max_error_m"),
        "final_error_m": over_ran(np.mean, "final_error_m"),
        "collisions": int(sum(r["collided"] for r in runs)),
        "person_collisions": int(sum(r.get("person_collisions", 0) for r in runs)),
        "no_way": int(sum(r.get("no_way", False) for r in runs)),
        "timeouts": int(sum(not r["route_done"] and not r["collided"] for r in runs)),
        "errors": int(sum(r["error"] for r in runs)),
        "realtime_factor": over_ran(np.median, "realtime_factor"),
        "replans": int(sum(r.get("replans", 0) for r in runs)),
    }


LOCALIZED_WITHIN_M = 0.1
"""An unknown-start run converged well when its handover is within this of the truth [m]."""


def localization_summary(runs: list[dict]) -> dict:
    """Per-mode global-localization figures of unknown-start run records."""
    ran = [r for r in runs if not r["error"]]
    converged = [r for r in ran if r["converged"]]
    times = [r["time_to_converge_s"] for r in converged]
    errors = [r["converged_error_m"] for r in converged]
    return {
        "converged_rate": len(converged) / len(runs),
        "converged_within_10cm_rate": sum(e <= LOCALIZED_WITHIN_M for e in errors) / len(runs),
        "mean_time_to_converge_s": float(np.mean(times)) if times else None,
        "max_time_to_converge_s": float(np.max(times)) if times else None,
        "mean_converged_error_m": float(np.mean(errors)) if errors else None,
        "wrong_convergences": int(sum(r["wrong_convergence"] for r in ran)),
        "collisions_before_converged": int(sum(r["collided_before_converged"] for r in ran)),
    }


def run_line(record: dict) -> dict:
    """The per-task part of a run record for the report (JSON-safe)."""
    keys = ("plan", "task", "route", "success", "collided", "person_collisions", "replans")
    line = {k: record[k] for k in keys}
    line["max_error_m"] = None if np.isnan(record["max_error_m"]) else record["max_error_m"]
    line["message"] = record["message"]
    return line


def print_report(
    report: dict, seed: int, rotate_deg: float, sigma_m: float, world: WorldOptions
) -> None:
    """The human summary of a navigation ``report`` (``evaluate``'s dict)."""
    print(
        f"{report['tasks']} tasks on {report['plans']} plans (seed {seed}, rotated "
        f"{rotate_deg:g} deg, odometry sigma {sigma_m * 1000:.0f} mm/step, "
        f"margin {report['margin_m']:.2f} m)"
    )
    if not world.is_plan:
        print(
            f"building: furniture on {world.clutter_fraction * 100:.0f} % of each room's floor, "
            f"{world.people} people, {world.closed_doors} closed doors, walls displaced by up to "
            f"{world.deviation_m * 100:.0f} cm"
        )
    print(
        f"{'mode':12s} {'success':>8s} {'mean err':>9s} {'max err':>8s} {'collisions':>10s}"
        f" {'people':>6s} {'realtime':>9s}"
    )

    def cm(value: float | None) -> str:
        return "     n/a" if value is None else f"{value * 100:6.1f}cm"

    for m, s in report["modes"].items():
        realtime = "n/a" if s["realtime_factor"] is None else f"{s['realtime_factor']:.0f}x"
        print(
            f"{m:12s} {s['success_rate'] * 100:7.1f}% {cm(s['mean_error_m'])}  "
            f"{cm(s['max_error_m'])} {s['collisions']:10d} {s['person_collisions']:6d} "
            f"{realtime:>9s}"
        )
    for m, lines in report["runs"].items():
        for r in (r for r in lines if not r["success"]):
            print(f"  {m} failed: plan {r['plan']} task {r['task']} ({r['route']}): {r['message']}")
    no_way = max(s["no_way"] for s in report["modes"].values())
    if no_way:
        print(f"{no_way} tasks' buildings leave the robot no way to the goal")
    if report["realtime_factor"] is not None:
        print(f"realtime factor (median of all runs): {report['realtime_factor']:.0f}x")
    if "global_localization" in report:
        print_localization(report["global_localization"])
    if report["replan"]:
        print("replans: " + ", ".join(f"{m} {s['replans']}" for m, s in report["modes"].items()))


def print_localization(summaries: dict) -> None:
    """The global-localization table of an unknown-start report."""
    print("unknown start (global localization before the route):")
    print(
        f"{'mode':12s} {'converged':>9s} {'<=10cm':>7s} {'mean t':>7s} {'max t':>7s}"
        f" {'wrong':>5s} {'collisions before':>17s}"
    )
    for m, s in summaries.items():
        mean_t, max_t = s["mean_time_to_converge_s"], s["max_time_to_converge_s"]
        seconds = lambda t: "    n/a" if t is None else f"{t:6.1f}s"
        within = s["converged_within_10cm_rate"]
        print(
            f"{m:12s} {s['converged_rate'] * 100:8.1f}% {within * 100:6.1f}%"
            f" {seconds(mean_t)} {seconds(max_t)} {s['wrong_convergences']:5d}"
            f" {s['collisions_before_converged']:17d}"
        )

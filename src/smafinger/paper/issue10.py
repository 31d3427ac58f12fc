"""report.md's sections on the studies (:mod:`.studies`): the hysteresis change of issue 10
(Figs. 12, 13 and 15 before and after, and the step-size check), the Fig. 15 cycles under each
damping rule and thermal reading, and the time each move takes.

Tables are built as data first (:func:`study_tables`, also written to ``investigation.json``);
every sentence of the findings is computed from them (:mod:`.cycle_findings`).
"""

from __future__ import annotations

from typing import Mapping

from ..metrics import reduction
from .derived import Run
from .fig15 import PAPER_REDUCTION, PAPER_S, REACH, REACH_V1, SCHEDULE, SCHEDULE_V1, STRATEGY_NAMES
from .fmt import md_escape, num, pct, secs
from .scenarios import get
from .studies import AS_SPECIFIED, CYCLE, DEADBAND, FINE_STEP, HYSTERESIS, Variant

STRATEGIES = tuple(STRATEGY_NAMES)
#: when a move is over, as the per-move table reads it: (key in a move's detail, words)
MOVE_ENDS = (("reached_s", "reached (within tol_deg for hold_s)"),
             ("settle_s", "settled within 0.1 deg to the end of its 10 s"),
             ("rest_s", "at rest (below 0.05 deg/s) to the end of its 10 s"),
             ("reached_cooled_s", "reached, and the wires it began with partly austenite back to martensite"))
#: the variants of the per-move table (on the 10 s schedule runs)
MOVE_VARIANTS = (AS_SPECIFIED, DEADBAND, FINE_STEP)
#: the rows of the Fig. 15 table, in order (then smafinger 0.1's independent runs)
CYCLE_ORDER = ("as-specified", "enabled", "cdf-heating", "cdf-cooling", FINE_STEP.key, "cdf-heating-0.1ms",
               "cdf-cooling-0.1ms", "two-node", "tamb60", DEADBAND.key)
#: smafinger 0.1's independent runs as a row of the Fig. 15 table (their own scenarios, not a variant)
V1_ROW = Variant("v1", "independent strategy of smafinger 0.1 (v1 runs: the strategy picks each move's agonist, so the "
                 "returns use the antagonist)", "strategy", short="v1 independent strategy")
#: the hysteresis table's columns: (variant, heading)
HYST_COLUMNS = ((DEADBAND, "before: dead band, 1 ms"), (AS_SPECIFIED, "after: memory, 1 ms"),
                (FINE_STEP, "after, 0.1 ms step"), (HYSTERESIS.variant("algebraic"), "after, algebraic stress law"))


def _ok(run: Run | None) -> Run | None:
    return run if run is not None and run.ok else None


def _derived(run: Run | None) -> dict | None:
    return None if run is None else run.derived


# ---------------------------------------------------------------------------------------
# tables (data)
# ---------------------------------------------------------------------------------------
def _hyst_cell(d: dict | None) -> dict | None:
    """A Figs. 12-15 run in brief: a move-and-return or a cycle."""
    if d is None:
        return None
    if "return" in d:
        return {"move_s": d["move"]["reached_s"], "return_s": d["return"]["reached_s"],
                "return_settle_s": d["return"]["settle_s"], "final_deg": d["return"]["final_deg"]}
    return {"cycle_s": d["cycle_s"], "reached_s": [m["reached_s"] for m in d["moves"]],
            "final_deg": d["moves"][-1]["final_deg"] if d["moves"] else None}


def hysteresis_table(runs: Mapping[str, Run]) -> list[dict]:
    """One row per run of the hysteresis study: each column's brief (``None``: not run)."""
    return [{"scenario": n, **{v.key: _hyst_cell(_derived(HYSTERESIS.run(runs, v, n))) for v, _ in HYST_COLUMNS
                               if v.applies(n)}}
            for n in HYSTERESIS.scenarios if runs.get(n) is not None]


def _cycle_row(v: Variant, names: dict[str, dict[str, Run | None]]) -> dict:
    row = {"key": v.key, "reading": v.label, "short": v.name}
    for kind in ("reach", "schedule"):
        t = {k: None if names[kind][k] is None else names[kind][k].derived["cycle_s"] for k in STRATEGIES}
        row.update({f"{kind}_{k}_s": t[k] for k in STRATEGIES})
        row[f"{kind}_reduction"] = reduction(t["independent"], t["cooperative"])
    return row


def _study_runs(study, variant: Variant, runs: Mapping[str, Run]) -> dict[str, dict[str, Run | None]]:
    return {kind: {k: study.run(runs, variant, n[k]) for k in STRATEGIES}
            for kind, n in (("reach", REACH), ("schedule", SCHEDULE))}


def cycle_table(runs: Mapping[str, Run]) -> list[dict]:
    """The Fig. 15 cycles (on reach and on a 10 s schedule) under each reading: the scenarios
    as specified, the cycle study's variants, the hysteresis study's, and smafinger 0.1's
    independent runs (v1)."""
    rows = {v.key: _cycle_row(v, _study_runs(CYCLE, v, runs)) for v in (AS_SPECIFIED, *CYCLE.variants)}
    rows.update({v.key: _cycle_row(v, _study_runs(HYSTERESIS, v, runs)) for v in (DEADBAND, FINE_STEP)})
    rows = [rows[k] for k in CYCLE_ORDER]
    v1 = {kind: {k: _ok(runs.get(n[k])) for k in STRATEGIES} for kind, n in (("reach", REACH_V1), ("schedule", SCHEDULE_V1))}
    rows.append(_cycle_row(V1_ROW, v1))
    return rows


def move_table(runs: Mapping[str, Run]) -> list[dict]:
    """The time each move of the 10 s schedule runs takes, by when a move is over
    (:data:`MOVE_ENDS`), per variant and strategy; ``None``: not within its 10 s."""
    rows = []
    for v in MOVE_VARIANTS:
        for k in STRATEGIES:
            run = HYSTERESIS.run(runs, v, SCHEDULE[k])
            if run is None:
                continue
            for key, words in MOVE_ENDS:
                times = [m[key] for m in run.derived["moves"]]
                rows.append({"variant": v.key, "variant_label": v.label, "variant_short": v.name, "strategy": k,
                             "end": key, "ends": words,
                             "moves_s": times, "paper_per_move_s": PAPER_S[k] / len(times),
                             "mean_s": None if any(x is None for x in times) else sum(times) / len(times)})
    return rows


def study_tables(runs: Mapping[str, Run]) -> dict:
    """Every study table (for ``investigation.json`` and the report)."""
    return {"hysteresis": hysteresis_table(runs), "cycles": cycle_table(runs), "moves": move_table(runs)}


# ---------------------------------------------------------------------------------------
# markdown
# ---------------------------------------------------------------------------------------
def _brief(c: dict | None) -> str:
    if c is None:
        return ""
    if "return_s" in c:
        return (f"move {secs(c['move_s'])}, return {secs(c['return_s'])} (settled {secs(c['return_settle_s'])}; "
                f"ends at {num(c['final_deg'], '.2f')} deg)")
    return f"cycle {secs(c['cycle_s'])}: " + ", ".join(num(x) for x in c["reached_s"])


def hysteresis_section(table: list[dict]) -> list[str]:
    from .cycle_findings import hysteresis_findings

    lines = ["## Issue 10: Figs. 12, 13 and 15 before and after the hysteresis change", "",
             "Each run as specified before the change (smafinger 0.1's dead-band rule, `hysteresis = deadband`), "
             "after it (return-point memory, the paper2010 sets' default), after it at a ten times finer step, and "
             "(Fig. 12) after it with the algebraic stress law. Times in s: for a move-and-return its `reached_s`; for "
             "a cycle its cycle time and each move's `reached_s`. Empty: not run in that column.", "",
             "| Run | " + " | ".join(h for _, h in HYST_COLUMNS) + " |", "|---|" + "---|" * len(HYST_COLUMNS)]
    for row in table:
        lines.append(f"| `{row['scenario']}` | " + " | ".join(_brief(row.get(v.key)) for v, _ in HYST_COLUMNS) + " |")
    return lines + [""] + hysteresis_findings(table) + [""]


def cycle_section(table: list[dict], moves: list[dict]) -> list[str]:
    from .cycle_findings import cycle_findings, move_findings

    lines = ["## Fig. 15: the faithful cycles, the damping rules and the readings", "",
             f"The independent runs as Sec. 4.1 describes them (`{REACH['independent']}`, "
             f"`{SCHEDULE['independent']}`: one actuator per move, the antagonist a passive bias spring) and the "
             f"co-operative runs (`{REACH['cooperative']}`, `{SCHEDULE['cooperative']}`), each row changing one thing. "
             "`never` = not completed in the simulated time.", "",
             "| Reading | Independent, on reach | Co-operative, on reach | Reduction | Independent, 10 s schedule "
             "| Co-operative, 10 s schedule | Reduction |", "|---|---|---|---|---|---|---|"]
    for r in table:
        lines.append(f"| {md_escape(r['reading'])} | " + " | ".join(
            [secs(r["reach_independent_s"]), secs(r["reach_cooperative_s"]), pct(r["reach_reduction"]),
             secs(r["schedule_independent_s"]), secs(r["schedule_cooperative_s"]), pct(r["schedule_reduction"])]) + " |")
    lines.append(f"| **paper** | **{PAPER_S['independent']:g} s** | **{PAPER_S['cooperative']:g} s** | "
                 f"**{pct(PAPER_REDUCTION)}** | | | |")
    lines += ["", *cycle_findings(table), "", "### How long a move takes (the paper's 'almost 10 s')", "",
              f"{PAPER_S['independent']:g} s / 4 moves = {PAPER_S['independent'] / 4:.2f} s and "
              f"{PAPER_S['cooperative']:g} s / 3 moves = {PAPER_S['cooperative'] / 3:.2f} s per move. The moves of the "
              "10 s schedule runs, by when a move counts as over (`never`: not within its 10 s):", "",
              "| Reading | Strategy | A move is over when | Each move | Mean | Paper's mean |", "|---|---|---|---|---|---|"]
    for m in moves:
        lines.append(f"| {md_escape(m['variant_label'])} | {STRATEGY_NAMES[m['strategy']]} | {m['ends']} | "
                     + ", ".join(secs(x) for x in m["moves_s"]) + f" | {secs(m['mean_s'], '.2f')} | "
                     f"{m['paper_per_move_s']:.2f} s |")
    return lines + ["", *move_findings(moves, table), ""]


def energy_note() -> str:
    """What the two energies are, with the factor between them for the paper's set."""
    p = get(REACH["independent"]).parameters()
    return (f"Energy is named for what it is: *heat* is what the model's Eq. (11) puts into a wire; *electrical* is "
            f"the energy at its terminals (V^2 / (R_w L_w)). With `joule_heating = {p.joule_heating}` (Eq. 11 read "
            f"literally, the paper's sets) the electrical energy is 1 / L_w^2 = {1 / p.wire_length_m ** 2:.2f} times "
            f"the heat (L_w = {p.wire_length_m:g} m): at {p.V_H_V:g} V, "
            f"{p.V_H_V ** 2 / (p.resistance_ohm_per_m * p.wire_length_m):.1f} W at the terminals against "
            f"{p.V_H_V ** 2 / p.resistance_ohm_per_m * p.wire_length_m:.2f} W of heat.")


__all__ = ["study_tables", "hysteresis_table", "cycle_table", "move_table", "hysteresis_section", "cycle_section",
           "energy_note", "MOVE_ENDS"]

"""The findings of the Fig. 15 investigation, each sentence computed from the table.

Every comparison in the text (within the tolerance or not, below or above, the largest
change, which reading comes closest) is evaluated on the numbers of
:func:`.investigation.table`; nothing is fixed prose except the names of the readings.
"""

from __future__ import annotations

from .claim import between, known, within
from .fig15 import PAPER_REDUCTION, PAPER_S, REDUCTION_BAND, STRATEGY_NAMES, TIME_TOLERANCE
from .fmt import pct, secs, span
from .investigation import READINGS, T_END_S
from .scenario import MOVE_S

STRATEGIES = tuple(STRATEGY_NAMES)
NAMES = STRATEGY_NAMES


def _pair(r: dict) -> str:
    return f"{secs(r['independent_s'])} / {secs(r['cooperative_s'])}"


def _topic(rows: dict, topic: str) -> list:
    return [(rd, rows[rd.key]) for rd in READINGS if rd.topic == topic and rd.key in rows]


def _of_paper(r: dict) -> str:
    return " / ".join(pct(None if r[f"{k}_s"] is None else r[f"{k}_s"] / PAPER_S[k]) for k in STRATEGIES)


def _within(r: dict) -> dict[str, bool]:
    return {k: within(r[f"{k}_s"], PAPER_S[k], TIME_TOLERANCE) for k in STRATEGIES}


def _unfinished(rd, r: dict) -> str:
    left = [k for k in STRATEGIES if r[f"{k}_s"] is None]
    if not left:
        return ""
    return (f"; {rd.short}: the {' and '.join(NAMES[k] for k in left)} cycle does not finish within {T_END_S:g} s (largest "
            f"co-operative overshoot of a target {r['cooperative_overshoot_deg']:.2f} deg)")


def reached(rows: dict, base: dict) -> str:
    items = _topic(rows, "reached")
    if not items:
        return ""
    n = len(base["independent_reached_s"] or ()) or 1
    done = [r for _, r in items if known(r["independent_s"], r["cooperative_s"])]
    text = ("- What 'reached' means: " + ", ".join(f"{rd.short} {_pair(r)}" for rd, r in items)
            + f", against {_pair(base)} as specified")
    if done and known(base["independent_s"], base["cooperative_s"]):
        d = max(abs(r[f"{k}_s"] - base[f"{k}_s"]) for r in done for k in STRATEGIES)
        rel = max(abs(r[f"{k}_s"] / base[f"{k}_s"] - 1) for r in done for k in STRATEGIES)
        text += f": where both cycles finish, at most {d / n:.1f} s per target ({pct(rel)} of a cycle)"
    return text + "".join(_unfinished(rd, r) for rd, r in items) + "."


def wait(rows: dict, base: dict) -> str:
    items = [(rd, r) for rd, r in _topic(rows, "wait") if r["reduction"] is not None]
    if not items:
        return ""
    best_rd, best = min(items, key=lambda x: abs(x[1]["reduction"] - PAPER_REDUCTION))
    return ("- When the independent strategy may use the antagonist: "
            + "; ".join(f"{rd.short}: {secs(r['independent_s'])} ({pct(r['reduction'])} reduction)" for rd, r in items)
            + f". Closest to the paper's {pct(PAPER_REDUCTION)} reduction: {best_rd.short} "
            f"({pct(best['reduction'])}), with times at {_of_paper(best)} of the paper's.")


def temperature(rows: dict, base: dict) -> str:
    parts = []
    for rd, r in _topic(rows, "temperature"):
        w = _within(r)
        if all(w.values()):
            verdict = f"both times within {pct(TIME_TOLERANCE)} of the paper's"
        elif any(w.values()):
            yes = next(k for k in STRATEGIES if w[k])
            no = next(k for k in STRATEGIES if not w[k])
            verdict = (f"the {NAMES[yes]} cycle within {pct(TIME_TOLERANCE)} of {PAPER_S[yes]:g} s but not the {NAMES[no]} one "
                       f"({_of_paper(r)} of the paper's), so it does not explain the pair")
        else:
            verdict = f"{_of_paper(r)} of the paper's"
        parts.append(f"{rd.short} {_pair(r)} ({pct(r['reduction'])}): {verdict}")
    return ("- Temperatures: " + "; ".join(parts) + ".") if parts else ""


def controller(rows: dict, base: dict) -> str:
    items = _topic(rows, "controller")
    if not items:
        return ""
    d = [abs(r[f"{k}_s"] - base[f"{k}_s"]) for _, r in items for k in STRATEGIES
         if known(r[f"{k}_s"], base[f"{k}_s"])]
    text = "- Controller and friction options: " + ", ".join(f"{rd.short} {_pair(r)}" for rd, r in items)
    if d:
        text += f": at most {max(d):.1f} s from the {_pair(base)} as specified"
    return text + "".join(_unfinished(rd, r) for rd, r in items) + "."


def schedule(rows: dict, base: dict) -> str:
    items = dict((rd.key, (rd, r)) for rd, r in _topic(rows, "schedule"))
    if "sched" not in items:
        return ""
    rd, r = items["sched"]
    w = _within(r)
    moves = {k: len(r[f"{k}_reached_s"] or ()) for k in STRATEGIES}
    paper_last = {k: PAPER_S[k] - (moves[k] - 1) * MOVE_S for k in STRATEGIES}
    ours_last = {k: (r[f"{k}_reached_s"] or [None])[-1] for k in STRATEGIES}
    same = len(set(paper_last.values())) == 1
    text = (f"- A **time schedule**, one move every {MOVE_S:g} s, {rd.short}: {_pair(r)} ({pct(r['reduction'])}) "
            f"against the paper's {PAPER_S['independent']:g} s / {PAPER_S['cooperative']:g} s "
            f"({pct(PAPER_REDUCTION)}): "
            + (f"both within {pct(TIME_TOLERANCE)}" if all(w.values()) else f"{_of_paper(r)} of them") + ". "
            + "The paper's times split the same way: "
            + " and ".join(f"{PAPER_S[k]:g} = {moves[k] - 1} x {MOVE_S:g} + {paper_last[k]:g}" for k in STRATEGIES)
            + (f" (the same {paper_last['independent']:g} s for the last move)" if same else " s")
            + f"; smafinger's last moves take {secs(ours_last['independent'])} and {secs(ours_last['cooperative'])}. "
            f"The period is the paper's own 'almost {MOVE_S:g} s' cooling phase (Fig. 12), not a fitted value: "
            f"the cycle times move by {moves['independent'] - 1} and {moves['cooperative'] - 1} times any change of it.")
    if "sched-direct" in items:
        rd2, r2 = items["sched-direct"]
        text += f" {rd2.short[0].upper() + rd2.short[1:]}: {_pair(r2)} ({pct(r2['reduction'])})."
    return text


def conclusion(rows: dict, base: dict) -> str:
    all_items = [(rd, rows[rd.key]) for rd in READINGS if rd.key in rows]
    reach = [(rd, r) for rd, r in all_items if rd.topic != "schedule"]
    both = [f"{rd.short} ({_pair(r)})" for rd, r in all_items if all(_within(r).values())]
    one = [rd.short for rd, r in reach if sum(_within(r).values()) == 1]
    t = {k: [r[f"{k}_s"] for _, r in reach if r[f"{k}_s"] is not None] for k in STRATEGIES}
    text = (f"- Conclusion: readings with both times within {pct(TIME_TOLERANCE)} of the paper's: "
            + ("; ".join(both) or "none") + ". ")
    if all(t.values()):
        ratio = {k: span([100 * x / PAPER_S[k] for x in t[k]], "%", ".0f") for k in STRATEGIES}
        text += (f"With targets issued on reach, the {len(reach)} readings give {span(t['independent'])} "
                 f"(independent) and {span(t['cooperative'])} (co-operative; {len(t['cooperative'])} of "
                 f"{len(reach)} finish): {ratio['independent']} and {ratio['cooperative']} of the paper's times")
        text += (f"; only {', '.join(one)} brings one of the two within {pct(TIME_TOLERANCE)}. " if one else ". ")
    red = base["reduction"]
    if red is not None:
        text += (f"The co-operative reduction as specified ({pct(red)}) is "
                 f"{'below' if red < PAPER_REDUCTION else 'above'} the paper's {pct(PAPER_REDUCTION)} and "
                 f"{'inside' if between(red, *REDUCTION_BAND) else 'outside'} the "
                 f"{pct(REDUCTION_BAND[0])}-{pct(REDUCTION_BAND[1])} band. ")
    return text + ("No parameter was tuned for these numbers; every reading uses the scenario's parameters "
                   "with the one change listed.")


SECTIONS = (reached, wait, temperature, controller, schedule, conclusion)


def findings(rows: list[dict]) -> list[str]:
    """The findings, one markdown bullet per topic and a conclusion."""
    by_key = {r["key"]: r for r in rows}
    base = by_key.get(READINGS[0].key)
    if base is None:
        return []
    lines = [s(by_key, base) for s in SECTIONS]
    return ["**Findings** (independent / co-operative cycle times):", ""] + [x for x in lines if x]


__all__ = ["findings"]

"""The findings of the studies' tables (:mod:`.issue10`), each sentence computed from them.

Every comparison (which targets are lost, which reading comes closest, whether a time is
within the tolerance, whether two runs agree) is evaluated on the numbers; nothing is fixed
prose except the names of the readings.
"""

from __future__ import annotations

from .claim import known, within
from .fig15 import PAPER_S, STRATEGY_NAMES, TIME_TOLERANCE
from .fmt import pct, secs
from .scenario import MOVE_S
from .studies import C_DF, DEADBAND, FINE_STEP

STRATEGIES = tuple(STRATEGY_NAMES)
KINDS = {"reach": "on reach", "schedule": "on the 10 s schedule"}
#: the hysteresis table's columns read by the findings
BEFORE, AFTER, FINE, ALG = DEADBAND.key, "as-specified", FINE_STEP.key, "algebraic"


# ---------------------------------------------------------------------------------------
# the hysteresis change
# ---------------------------------------------------------------------------------------
def _targets(c: dict | None) -> list:
    """The reach times of a brief (move-and-return or cycle), in order."""
    if c is None:
        return []
    return [c["move_s"], c["return_s"]] if "return_s" in c else list(c["reached_s"])


def _deviation(c: dict | None, target: float) -> float | None:
    return None if c is None or c.get("final_deg") is None else abs(c["final_deg"] - target)


def hysteresis_findings(table: list[dict]) -> list[str]:
    if not table:
        return []
    reached = lost = checked = recovered = 0
    names = []
    for row in table:
        before, after, fine = (_targets(row.get(k)) for k in (BEFORE, AFTER, FINE))
        for j, b in enumerate(before):
            if b is None:
                continue
            reached += 1
            if j < len(after) and after[j] is None:
                lost += 1
                names.append(f"`{row['scenario']}` move {j + 1}")
                if row.get(FINE) is not None:
                    checked += 1
                    recovered += int(j < len(fine) and fine[j] is not None)
    rest = -40.0
    dev = {k: [d for row in table if "return_s" in (row.get(k) or {}) for d in [_deviation(row[k], rest)]
               if d is not None] for k in (BEFORE, AFTER, FINE, ALG)}
    lines = [f"- Reached before the change (dead band, 1 ms): {reached} targets. Not reached after it at 1 ms: "
             f"{lost}" + (f" ({', '.join(names)})" if names else "") + "."]
    if checked:
        lines[-1] += f" Of the {checked} of these run at 0.1 ms, {recovered} are reached."
    if all(dev[k] for k in (BEFORE, AFTER)):
        text = (f"- Where each move-and-return ends: at most {max(dev[BEFORE]):.2f} deg from -40 deg before the "
                f"change, {max(dev[AFTER]):.2f} deg after it at 1 ms")
        text += f", {max(dev[FINE]):.2f} deg at 0.1 ms" if dev[FINE] else ""
        text += (f", {max(dev[ALG]):.2f} deg with the algebraic stress law" if dev[ALG] else "") + "."
        lines.append(text)
    cyc = [row for row in table if "cycle_s" in (row.get(AFTER) or {})]
    diffs = {k: [abs(row[k]["cycle_s"] - row[BEFORE]["cycle_s"]) for row in cyc
                 if row.get(k) is not None and known(row[k]["cycle_s"], (row.get(BEFORE) or {}).get("cycle_s"))]
             for k in (AFTER, FINE)}
    if diffs[AFTER]:
        text = (f"- Fig. 15 cycles finished in both columns change by at most {max(diffs[AFTER]):.1f} s from before to "
                f"after at 1 ms ({len(diffs[AFTER])} cycles)")
        if diffs[FINE]:
            text += f", and by at most {max(diffs[FINE]):.1f} s from before to after at 0.1 ms ({len(diffs[FINE])} cycles)"
        lines.append(text + ".")
    if checked and recovered == checked:
        text = ("- So what the change broke at 1 ms is the step, not the hysteresis rule: every target lost at 1 ms "
                "is reached at 0.1 ms")
        if dev[FINE] and dev[ALG]:
            text += (f"; at 0.1 ms the returns end within {max(dev[FINE]):.2f} deg of -40 deg, and with the algebraic "
                     f"stress law (no integrated stress) within {max(dev[ALG]):.2f} deg at 1 ms")
        lines.append(text + ".")
    elif checked:
        lines.append(f"- {checked - recovered} of the {checked} targets lost at 1 ms and run at 0.1 ms are not reached "
                     "there either.")
    return lines + [x for x in (_step_agreement(table),) if x]


def _step_agreement(table: list[dict]) -> str:
    """The scenarios' 1 ms step against the ten times finer one, target by target (after the change)."""
    diffs, one_only = [], []
    for row in table:
        if row.get(FINE) is None:
            continue
        after, fine = _targets(row.get(AFTER)), _targets(row.get(FINE))
        for j, (a, f) in enumerate(zip(after, fine)):
            name = f"`{row['scenario']}` move {j + 1}"
            if known(a, f):
                diffs.append((abs(a - f), name))
            elif known(a) or known(f):
                one_only.append(name)
    if not diffs:
        return ""
    d = sorted(diffs)
    text = (f"- The 1 ms step against 0.1 ms (after the change): {len(d)} targets reached at both, their reach times "
            f"{d[len(d) // 2][0] * 1e3:.1f} ms apart at the median and at most {d[-1][0] * 1e3:.1f} ms "
            f"({d[-1][1]})")
    if one_only:
        text += f"; reached at one step only: {', '.join(one_only)}"
    return text + "."


# ---------------------------------------------------------------------------------------
# the Fig. 15 cycles
# ---------------------------------------------------------------------------------------
def _pair(r: dict, kind: str) -> str:
    return (f"{secs(r[f'{kind}_independent_s'])} / {secs(r[f'{kind}_cooperative_s'])} "
            f"({pct(r[f'{kind}_reduction'])})")


def _same_coop(rows: list[dict], kind: str) -> bool:
    t = [r[f"{kind}_cooperative_s"] for r in rows]
    return known(*t) and len(set(t)) == 1


def _saved(row: dict | None, kind: str) -> float | None:
    """Seconds the co-operative cycle saves against the independent one (``None`` if either is missing)."""
    if row is None or not known(row[f"{kind}_independent_s"], row[f"{kind}_cooperative_s"]):
        return None
    return row[f"{kind}_independent_s"] - row[f"{kind}_cooperative_s"]


#: the damping comparisons: (step, the set's switching rule, the enable rule, one heating C_DF, one cooling C_DF)
DAMPING_GROUPS = (("1 ms", "as-specified", "enabled", "cdf-heating", "cdf-cooling"),
                  ("0.1 ms", FINE_STEP.key, None, "cdf-heating-0.1ms", "cdf-cooling-0.1ms"))


def _damping(by: dict) -> list[str]:
    out = []
    for step, switching, enabled, heating, cooling in DAMPING_GROUPS:
        names = {switching: "the set's heating-phase switching", enabled: "the authors' enable rule",
                 heating: f"one C_DF of {C_DF['heating']:g} throughout",
                 cooling: f"one C_DF of {C_DF['cooling']:g} throughout"}
        keys = [k for k in (switching, enabled, heating, cooling) if k is not None and k in by]
        if len(keys) < 2 or switching not in keys:
            continue
        for kind, words in KINDS.items():
            text = f"- Damping at {step}, {words} (independent / co-operative): " + "; ".join(
                f"{names[k]} {_pair(by[k], kind)}" for k in keys) + "."
            same = [k for k in (switching, enabled, heating) if k in keys]
            if len(same) > 1 and _same_coop([by[k] for k in same], kind):
                text += (" The co-operative cycle is the same under " + ", ".join(names[k] for k in same) + ": one of "
                         "its wires is always in its heating phase, so its C_DF never leaves the heating value.")
            if enabled in keys and heating in keys and all(
                    by[enabled][f"{kind}_{k}_s"] == by[heating][f"{kind}_{k}_s"] for k in STRATEGIES):
                text += (" The enable rule gives exactly the one-C_DF times: in these runs an actuator is always "
                         "enabled.")
            saved = {k: _saved(by.get(k), kind) for k in (switching, heating)}
            if known(*saved.values()) and saved[switching] > 0:
                own = saved[switching] - saved[heating]
                text += (f" Of the {saved[switching]:.1f} s the co-operative cycle saves with the switching, "
                         f"{own:.1f} s ({pct(own / saved[switching])}) come from the switching itself: with one C_DF "
                         f"it saves {saved[heating]:.1f} s.")
            out.append(text)
    return out


def _others(by: dict, keys: tuple[str, ...], title: str) -> str:
    have = [k for k in keys if k in by]
    if not have or "as-specified" not in by:
        return ""
    return (f"- {title}: " + "; ".join(f"{by[k]['short']}: " + ", ".join(f"{w} {_pair(by[k], kind)}"
                                                                            for kind, w in KINDS.items())
                                       for k in have)
            + ". As specified: " + ", ".join(f"{w} {_pair(by['as-specified'], kind)}" for kind, w in KINDS.items())
            + ".")


def _spans(rows: list[dict]) -> str:
    """The co-operative times over every reading, per kind of cycle, against the paper's."""
    parts = []
    for kind, words in KINDS.items():
        t = [r[f"{kind}_cooperative_s"] for r in rows if r[f"{kind}_cooperative_s"] is not None]
        if t:
            parts.append(f"{words} {min(t):.1f}-{max(t):.1f} s ({pct(min(t) / PAPER_S['cooperative'])}-"
                         f"{pct(max(t) / PAPER_S['cooperative'])} of it)")
    return (f"- The co-operative {PAPER_S['cooperative']:g} s over the {len(rows)} readings: " + "; ".join(parts) + "."
            if parts else "")


def _closest(rows: list[dict]) -> str:
    both = [f"{r['short']} {KINDS[kind]} ({_pair(r, kind)})" for r in rows for kind in KINDS
            if all(within(r[f"{kind}_{k}_s"], PAPER_S[k], TIME_TOLERANCE) for k in STRATEGIES)]
    coop = [(abs(r[f"{kind}_cooperative_s"] - PAPER_S["cooperative"]), r, kind) for r in rows for kind in KINDS
            if r[f"{kind}_cooperative_s"] is not None]
    text = (f"- Both cycle times within {pct(TIME_TOLERANCE)} of the paper's: " + ("; ".join(both) or "none") + ".")
    if coop:
        _, r, kind = min(coop, key=lambda x: x[0])
        text += (f" Closest co-operative time to the paper's {PAPER_S['cooperative']:g} s: "
                 f"{secs(r[f'{kind}_cooperative_s'])} ({r['short']}, {KINDS[kind]}).")
    return text


def cycle_findings(table: list[dict]) -> list[str]:
    by = {r["key"]: r for r in table}
    if "as-specified" not in by:
        return []
    lines = ["**Findings** (independent / co-operative cycle times, reduction):", ""]
    lines += _damping(by)
    lines += [x for x in (_others(by, ("two-node", "tamb60"), "Thermal readings (1 ms)"),
                          _others(by, (DEADBAND.key, FINE_STEP.key), "Hysteresis rule and step"),
                          _others(by, ("v1",), "smafinger 0.1's independent strategy")) if x]
    return lines + [x for x in (_spans(table), _closest(table)) if x]


# ---------------------------------------------------------------------------------------
# the moves
# ---------------------------------------------------------------------------------------
def move_findings(moves: list[dict], table: list[dict]) -> list[str]:
    if not moves:
        return []
    lines = []
    for k in STRATEGIES:
        rows = [m for m in moves if m["strategy"] == k and m["mean_s"] is not None]
        per = PAPER_S[k] / max(len(m["moves_s"]) for m in moves if m["strategy"] == k)
        if not rows:
            lines.append(f"- {STRATEGY_NAMES[k].capitalize()}: no definition has every move over within its 10 s.")
            continue
        best = min(rows, key=lambda m: abs(m["mean_s"] - per))
        ok = [m for m in rows if within(m["mean_s"], per, TIME_TOLERANCE)]
        lines.append(
            f"- {STRATEGY_NAMES[k].capitalize()} (paper: {per:.2f} s per move): closest mean {secs(best['mean_s'], '.2f')} "
            f"({best['ends']}; {best['variant_short']}); {len(ok)} of {len(rows)} complete definitions within "
            f"{pct(TIME_TOLERANCE)} of it.")
    lines.append(_schedule(table))
    return lines


def _schedule(table: list[dict]) -> str:
    """The paper's two times as n moves of MOVE_S plus a last move, against the schedule runs."""
    n = {"independent": 4, "cooperative": 3}
    last = {k: PAPER_S[k] - (n[k] - 1) * MOVE_S for k in STRATEGIES}
    same = len(set(last.values())) == 1
    text = ("- The paper's pair splits into moves of " f"{MOVE_S:g} s and a last move: "
            + " and ".join(f"{PAPER_S[k]:g} = {n[k] - 1} x {MOVE_S:g} + {last[k]:g}" for k in STRATEGIES)
            + (f", the same {last['independent']:g} s last move for both" if same else ""))
    base = next((r for r in table if r["key"] == "as-specified"), None)
    if base is not None and known(base["schedule_independent_s"], base["schedule_cooperative_s"]):
        ours = {k: base[f"schedule_{k}_s"] - (n[k] - 1) * MOVE_S for k in STRATEGIES}
        text += (f"; on the 10 s schedule smafinger's last moves end {secs(ours['independent'])} and "
                 f"{secs(ours['cooperative'])} into their 10 s")
    return text + "."


__all__ = ["hysteresis_findings", "cycle_findings", "move_findings"]

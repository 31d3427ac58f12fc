"""``report.md``: each claim beside smafinger's value and verdict; the studies (issue 10's
hysteresis change, the Fig. 15 cycles under each damping rule and reading, the time a move
takes) and smafinger 0.1's Fig. 15 investigation, with their computed findings; and the runs,
with the heat put into each wire and the electrical energy at its terminals. The narrative
behind the readings is in ``docs/reproduce.md``; every number and comparison here is computed
from the runs."""

from __future__ import annotations

from pathlib import Path

from .. import __version__
from ..parameters import get as get_params
from ..files import atomic_write
from .claim import Outcome, Verdict
from .derived import Run
from .fig15 import PAPER_REDUCTION, PAPER_S, REACH, REACH_V1
from .findings import findings
from .fmt import md_escape, num, pct, secs
from .issue10 import cycle_section, energy_note, hysteresis_section
from .scenario import OPEN_LOOP_ON_S, PAPER_FRICTION
from .scenarios import get
from .sec4 import PID
from .sec31 import PARAMS as TABLE2_NAME
from .sec31 import TABLE2

_CLAIMS_HEADER = ("| Figure | Claim | Paper | smafinger | Holds | Note |", "|---|---|---|---|---|---|")


def readings() -> list[str]:
    """The readings the paper's scenarios share, with their numbers from the sets and specs."""
    p = get_params("paper2010")
    base = get(REACH["independent"]).spec()
    tol, hold = base.tol_deg, base.hold_s
    return [
        "Readings common to the paper's scenarios (`smafinger scenarios -v` lists each run; the reasons are "
        "in docs/reproduce.md):",
        "",
        f"- Sec. 3.1 (Figs. 7-8 and the other variations): parameter set `{TABLE2_NAME}` (Table II: h0 = "
        f"{TABLE2.h0_heating_W_m2K:g}, h2 = {TABLE2.h2_heating_W_m2K3:g}, C_DF = {TABLE2.C_DF_heating_Nms:g}), open "
        f"loop, the set's V_H = {TABLE2.V_H_V:g} V on one wire for {OPEN_LOOP_ON_S:g} s, then removed; the "
        f"spring-length variations use `spring_init = given`, all others the set's `{TABLE2.spring_init}`.",
        f"- Figs. 10(a)-15: parameter set `{p.name}` (Sec. 3.2 coefficients, PID {PID} updated every "
        f"{p.controller_update_s:g} s, controller {'kept on' if p.controller_in_cooling else 'off'} in the "
        "cooling phase unless stated).",
        f"- Friction: `{' '.join(PAPER_FRICTION.texts())}` in every paper scenario: Sec. 3.1 neglects stick-slip "
        f"(purely viscous friction after the onset of motion); the `{p.name}` set's own default is "
        f"`{p.friction_sticking}` (smafinger 0.1's was `restick`).",
        f"- Damping: C_DF's heating value while a wire is in its controller's heating phase, its cooling value "
        f"otherwise (`damping_switch = {p.damping_switch}`); the Fig. 15 section gives the cycles under each rule.",
        f"- Hysteresis: `hysteresis = {p.hysteresis}` (return-point memory, the paper2010 sets' default since issue "
        "10); the section on issue 10 gives Figs. 12, 13 and 15 before and after.",
        f"- Times: a target counts as reached once within {tol:g} deg for {hold:g} s (`reached_s`, from the start "
        "of its segment). With targets issued on reach, a full-cycle time is the sum of the segments' `reached_s` "
        "(the cycle time); the time from t = 0 at which the last target is reached (given beside it, and dashed in "
        f"fig15.png) is longer by the {hold:g} s the engine waits to confirm each intermediate target. For a time "
        "schedule the two are the same.",
        "",
    ]


def _note(o: Outcome) -> str:
    parts = [o.note] if o.note else []
    gap = o.claim.known_gap
    if gap and o.verdict is Verdict.YES:
        parts.append("listed as a known gap, but it holds: the claim's known_gap should go")
    elif gap and o.verdict is not Verdict.NOT_RUN:
        parts.append(f"known not to hold: {gap}")
    if o.claim.checks:
        parts.append(f"criterion: {o.claim.criterion}")
    return "; ".join(parts)


def claims_table(outcomes: list[Outcome]) -> list[str]:
    """The claims evaluated, then a line naming those whose runs failed and one naming those not selected."""
    lines = ["## The paper's claims", "", *_CLAIMS_HEADER]
    for o in outcomes:
        if o.verdict is Verdict.NOT_RUN:
            continue
        c = o.claim
        cells = (c.figure, c.statement, c.paper, o.shows, o.verdict.value, _note(o))
        lines.append("| " + " | ".join(md_escape(x) for x in cells) + " |")
    broken = [o for o in outcomes if o.verdict is Verdict.NOT_RUN and o.runs_failed]
    skipped = [o.claim for o in outcomes if o.verdict is Verdict.NOT_RUN and not o.runs_failed]
    if broken:
        lines += ["", f"{len(broken)} claim(s) not evaluated because a run failed: "
                  + "; ".join(f"{o.claim.figure}: {o.claim.statement} ({', '.join(o.runs_failed)} failed)"
                              for o in broken) + "."]
    if skipped:
        lines += ["", f"{len(skipped)} claim(s) not run (their scenarios were not selected): "
                  + "; ".join(f"{c.figure}: {c.statement}" for c in skipped) + "."]
    return lines + [""]


def investigation_section(rows: list[dict]) -> list[str]:
    """smafinger 0.1's Fig. 15 readings table (v1 baseline) and its findings."""
    base = rows[0]
    lines = [
        "## Fig. 15: smafinger 0.1's readings (v1 runs)", "",
        f"The paper gives {PAPER_S['independent']:g} s (independent) and {PAPER_S['cooperative']:g} s "
        f"(co-operative) for the cycle. These readings start from smafinger 0.1's on-reach runs "
        f"(`{REACH_V1['independent']}`, `{REACH_V1['cooperative']}`), whose independent strategy uses the "
        "antagonist once the agonist's wire is back to martensite. Issuing each target as soon as the previous one "
        f"is reached, smafinger takes {secs(base['independent_s'])} and {secs(base['cooperative_s'])} ("
        + " and ".join(pct(None if base[f'{k}_s'] is None else base[f'{k}_s'] / PAPER_S[k]) for k in PAPER_S)
        + " of the paper's). Each reading below changes one thing from that baseline (co-operative times marked "
        "= are the baseline's run: the reading only concerns the independent strategy). Cycle time as defined "
        "under Readings; `never` = not completed in the simulated time.", "",
        "| Reading | Independent | Co-operative | Reduction | reached_s per segment (ind. / co-op.) |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        segs = " / ".join("[" + ", ".join(num(x) for x in (v or [])) + "]"
                          for v in (r["independent_reached_s"], r["cooperative_reached_s"]))
        co = ("= " if r["cooperative_shared_with_baseline"] else "") + secs(r["cooperative_s"])
        lines.append(f"| {md_escape(r['reading'])} | {secs(r['independent_s'])} | {co} | {pct(r['reduction'])} "
                     f"| {segs} |")
    lines.append(f"| **paper** | **{PAPER_S['independent']:g} s** | **{PAPER_S['cooperative']:g} s** | "
                 f"**{pct(PAPER_REDUCTION)}** | |")
    return lines + [""] + findings(rows) + [""]


def runs_section(runs: dict[str, Run], figures: list[Path]) -> list[str]:
    """The figures, the failed runs, and every scenario run's interlock count and wall time."""
    lines = ["## Figures", ""] + [f"- [{p.name}]({p.name})" for p in figures] + [""]
    failed = [r for r in runs.values() if not r.ok]
    if failed:
        lines += ["## Failed runs", ""] + [f"- `{r.key}`: {r.error}" for r in failed] + [""]
    lines += ["## Runs", "", energy_note(), "",
              "| Scenario | Figure | Interlock violations | Heat into the wires (upper / lower) | Electrical energy "
              "at the terminals (upper / lower) | Wall time |", "|---|---|---|---|---|---|"]
    for r in runs.values():
        if r.scenario is None:
            continue
        if not r.ok:
            lines.append(f"| `{r.key}` | {r.scenario.figure} | failed | | | |")
            continue
        heat, elec = (" / ".join(f"{r.summary[k][w]:.2f} J" for w in r.spec.params.wire_names)
                      for k in ("heat_J", "electrical_energy_J"))
        lines.append(f"| `{r.key}` | {r.scenario.figure} | {r.summary['interlock_violations']} | {heat} | {elec} | "
                     f"{1e3 * r.summary['wall_s']:.0f} ms |")
    return lines + [""]


def failed_runs_note(runs: dict[str, Run]) -> list[str]:
    """A line naming the failed runs, above the study tables, where a failed run's cells read
    ``never`` as a run that did not finish would (found by review); none if every run finished."""
    failed = [k for k, r in runs.items() if not r.ok]
    if not failed:
        return []
    return [f"**{len(failed)} run(s) failed: {', '.join(failed)}.** In the tables below a failed run's cells "
            "read `never`, as a run that did not finish in its time would; the findings drawn from them do "
            "not hold.", ""]


def write_report(path: Path, outcomes: list[Outcome], rows: list[dict] | None, runs: dict[str, Run],
                 figures: list[Path], wall_s: float, workers: int, tables: dict | None = None) -> None:
    """Write ``report.md`` (atomically); ``tables``: the studies' (:func:`.issue10.study_tables`)."""
    n_sc = sum(1 for r in runs.values() if r.scenario is not None)
    lines = ["# smafinger: reproduction of Gilardi et al., Robotica 28(5):675-687 (2010)", "",
             f"Generated by `smafinger reproduce` (smafinger {__version__}): {n_sc} scenario runs"
             + (f" and {len(runs) - n_sc} investigation runs" if len(runs) > n_sc else "")
             + f" on {workers} worker process(es), {wall_s:.1f} s in all.", ""]
    lines += readings() + claims_table(outcomes)
    if tables or rows:
        lines += failed_runs_note(runs)
    if tables and tables["hysteresis"]:
        lines += hysteresis_section(tables["hysteresis"])
    if tables and tables["cycles"]:
        lines += cycle_section(tables["cycles"], tables["moves"])
    if rows:
        lines += investigation_section(rows)
    lines += runs_section(runs, figures)
    text = "\n".join(lines)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text))


__all__ = ["write_report", "failed_runs_note", "readings", "claims_table", "investigation_section", "runs_section"]

"""How a run is shown on the terminal: its segments, energy, peaks and warnings."""

from __future__ import annotations

import sys


def print_run(result) -> None:
    """The segment table and the per-wire totals on stdout; the plausibility warnings on stderr."""
    from rich.console import Console
    from rich.table import Table

    m = result.summary()
    u = result.spec.params.coordinate.unit
    console = Console()
    changed = m["params_changed"]
    changed = (f" ({', '.join(changed) if len(changed) <= 3 else f'{len(changed)} fields'} changed)"
               if changed else "")
    table = Table(title=f"{m['params']}{changed} / {m['strategy']}  ({m['steps']} steps, {1e3 * m['wall_s']:.1f} ms)")
    for col in ("segment", "start [s]", f"target [{u}]", "reached [s]", f"overshoot [{u}]"):
        table.add_column(col, justify="right")
    fmt = ".2f" if u == "deg" else ".5f"
    for s in m["segments"]:
        reached = "never" if s["reached_s"] is None else f"{s['reached_s']:.3f}"
        over = s[f"overshoot_{u}"]  # None: no output sample in the segment (a target never pursued)
        table.add_row(str(s["index"]), f"{s['start_s']:.3f}", format(s[f"target_{u}"], fmt), reached,
                      "-" if over is None else format(over, fmt))
    console.print(table)
    wires = result.spec.params.wire_names
    e, pt, ps = m["energy_J"], m["peak_temperature_C"], m["peak_stress_Pa"]
    console.print(
        "energy [J] " + " ".join(f"{w} {e[w]:.2f}" for w in wires)
        + " | peak T [°C] " + " ".join(f"{w} {pt[w]:.1f}" for w in wires)
        + " | peak stress [MPa] " + " ".join(f"{w} {ps[w] / 1e6:.2f}" for w in wires)
        + f" | interlock violations {m['interlock_violations']}", highlight=False)
    if result.step_check is not None:
        console.print(result.step_check.describe(), highlight=False)
    sys.stdout.flush()
    for w in m["warnings"]:
        print(f"smafinger: warning: {w}", file=sys.stderr)

"""Where the compiled kernel spends its time: a sampling profile by address (a script, not a test).

The kernel inlines nearly every function (``forceinline``), and numba's code carries no symbols
``perf`` can read, so a profile by function says only "JIT". This script runs the co-operative
full cycle (45 s, ``paper2010``, the default numerics) in a child process under ``perf record``
for a few seconds and reads the samples by address instead:

- the share of the samples in the kernel's code, in ``libm`` (by function), in Python and the rest;
- within the kernel: the share of samples on an instruction just after a division or a square
  root (where a chain of them stalls), and the hottest 512-byte windows of code, each with the
  divisions, square roots and calls it holds.

The child writes the kernel's code (the executable mapping that holds its entry point, read
from ``/proc/self/maps``) to a file, which ``objdump`` disassembles. Needs ``perf`` and
``objdump`` on the PATH (Linux); says so and stops otherwise.

Usage::

    PYTHONPATH=src python benchmarks/bench_profile.py [--seconds 8] [--form loop|default]
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

#: the child: loads the kernel, saves its code's mapping, then runs the form for argv[2] seconds
_CHILD = """
import ctypes, dataclasses, sys, time
from smafinger.engine.kernel import run_kernel
from smafinger.engine.run import make_spec, run_spec
out, seconds, form = sys.argv[1], float(sys.argv[2]), sys.argv[3]
spec = make_spec("paper2010", "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=45.0)
if form == "loop":
    spec, record = dataclasses.replace(spec, output_interval_s=spec.t_end_s), "metrics"
else:
    record = "all"
run_spec(spec, record=record)  # compiled or loaded
(cres,) = run_kernel.overloads.values()
entry = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
for line in open("/proc/self/maps"):
    lo, hi = (int(x, 16) for x in line.split()[0].split("-"))
    if lo <= entry < hi:
        open(out + ".bin", "wb").write(ctypes.string_at(lo, hi - lo))
        open(out + ".range", "w").write(f"{lo} {hi}")
t0 = time.perf_counter()
n = 0
while time.perf_counter() - t0 < seconds:
    run_spec(spec, record=record)
    n += 1
print(n)
"""

_STALLERS = ("div", "sqrt")


def _disassembly(binary: Path, lo: int) -> list[tuple[int, str]]:
    text = subprocess.run(["objdump", "-D", "-b", "binary", "-mi386:x86-64", f"--adjust-vma={lo}", str(binary)],
                          check=True, capture_output=True, text=True).stdout
    out = []
    for line in text.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(?:[0-9a-f]{2} )+\s*(.*)", line)
        if m and m.group(2).strip():
            out.append((int(m.group(1), 16), m.group(2).strip()))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=8.0, help="how long the child runs the cycle")
    ap.add_argument("--form", choices=("loop", "default"), default="loop",
                    help="loop: the step loop, no samples between its ends; default: every signal every 1 ms")
    ap.add_argument("--top", type=int, default=8, help="how many of the hottest windows to print")
    a = ap.parse_args()
    missing = [tool for tool in ("perf", "objdump") if shutil.which(tool) is None]
    if missing:
        print(f"bench_profile: {' and '.join(missing)} not found on the PATH; nothing measured")
        return
    env = dict(os.environ, PYTHONPATH=str(SRC), SMAFINGER_ENGINE="compiled")
    with tempfile.TemporaryDirectory() as tmp:
        stem, data = Path(tmp, "kernel"), Path(tmp, "perf.data")
        subprocess.run([sys.executable, "-c", _CHILD, str(stem), "1", a.form],
                       env=env, check=True, capture_output=True)  # numba's cache filled, not counted
        rec = subprocess.run(["perf", "record", "-q", "-o", str(data), "--", sys.executable, "-c", _CHILD,
                              str(stem), str(a.seconds), a.form],
                             env=env, capture_output=True, text=True)
        if rec.returncode != 0:
            print(f"bench_profile: perf record failed ({rec.stderr.strip()[-300:]}); nothing measured")
            return
        runs = int(rec.stdout.strip().splitlines()[-1])
        lo, hi = (int(x) for x in stem.with_suffix(".range").read_text().split())
        samples = subprocess.run(["perf", "script", "-i", str(data), "-F", "ip,sym,dso"], check=True,
                                 capture_output=True, text=True).stdout.splitlines()
        code = _disassembly(stem.with_suffix(".bin"), lo)
    where = collections.Counter()
    libm = collections.Counter()
    ips = collections.Counter()
    for line in samples:
        parts = line.split()
        if not parts:
            continue
        ip = int(parts[0], 16)
        if lo <= ip < hi:
            where["the kernel (numba's code)"] += 1
            ips[ip] += 1
        elif "libm" in line:
            where["libm"] += 1
            libm[parts[1] if len(parts) > 2 else "?"] += 1
        elif "libpython" in line:
            where["Python"] += 1
        else:
            where["other (the C library, the OS, BLAS threads, ...)"] += 1
    total = sum(where.values())
    in_kernel = where["the kernel (numba's code)"]
    print(f"bench_profile: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} (1 min); the co-operative "
          f"full cycle (45 s), default numerics, form {a.form!r}: {runs} runs in {a.seconds:g} s, {total} samples")
    for name, n in where.most_common():
        print(f"   {name:48s}: {100 * n / total:5.1f} %")
    for name, n in libm.most_common(4):
        print(f"      libm {name:43s}: {100 * n / total:5.1f} %")
    after = 0
    for (_, prev), (addr, _) in zip(code, code[1:]):
        if any(s in prev.split()[0] for s in _STALLERS):
            after += ips[addr]
    print(f"   of the kernel's samples, on the instruction just after a division or square root: "
          f"{100 * after / max(in_kernel, 1):.1f} %")
    windows = collections.Counter()
    for ip, n in ips.items():
        windows[(ip - lo) // 512] += n
    print(f"   the kernel's hottest 512-byte windows of code (of {(hi - lo) // 1024} KB mapped), share of its samples:")
    for w, n in windows.most_common(a.top):
        ops = [op.split()[0] for addr, op in code if lo + 512 * w <= addr < lo + 512 * (w + 1)]
        counts = {k: sum(1 for o in ops if k in o) for k in ("div", "sqrt", "call")}
        print(f"      +{512 * w:#07x}: {100 * n / max(in_kernel, 1):5.1f} %  ({len(ops)} instructions: "
              f"{counts['div']} divisions, {counts['sqrt']} square roots, {counts['call']} calls)")


if __name__ == "__main__":
    main()

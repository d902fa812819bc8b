#!/usr/bin/env python3
"""Compares two `cargo build --timings` reports (cargo-timings/cargo-timing.html
in a target dir), as read for docs/ci.md: the build's end, the units'
durations summed, the whole machine's CPU use from cargo's graph, units at
work per 50 s window, the units whose duration changed most, and topple's own
targets (start, duration, front end and code generation where cargo gives
them). Standard library only.

    .ci/compare_timings.py A/cargo-timings/cargo-timing.html B/cargo-timings/cargo-timing.html
"""
import json
import re
import sys


def load(path):
    text = open(path, encoding="utf-8").read()
    units = json.loads(re.search(r"const UNIT_DATA = (\[.*?\]);\n", text, re.S).group(1))
    cpu = re.search(r"const CPU_USAGE = (\[.*?\]);\n", text, re.S)
    return units, json.loads(cpu.group(1)) if cpu else []


def end(units):
    return max(u["start"] + u["duration"] for u in units)


def busy_share(cpu):
    """Mean CPU use of the whole machine over the build, in %."""
    total, prev = 0.0, 0.0
    for t, pct in cpu:
        total += (t - prev) * pct
        prev = t
    return total / prev if prev else float("nan")


def at_work(units, window=50.0):
    """Units at work, averaged over each window of the build."""
    bins = {}
    for u in units:
        t, stop = u["start"], u["start"] + u["duration"]
        while t < stop:
            k = int(t // window)
            nxt = min((k + 1) * window, stop)
            bins[k] = bins.get(k, 0.0) + nxt - t
            t = nxt
    return [round(bins.get(k, 0.0) / window, 2) for k in range(int(end(units) // window) + 1)]


def key(u):
    return (u["name"], u["version"], u["target"].strip(), u["mode"])


def main(a_path, b_path):
    a, cpu_a = load(a_path)
    b, cpu_b = load(b_path)
    for name, units, cpu in (("A", a, cpu_a), ("B", b, cpu_b)):
        print(f"{name}: {len(units)} units, ends at {end(units):.1f} s, durations summed "
              f"{sum(u['duration'] for u in units):.1f} s, machine busy {busy_share(cpu):.0f} %")
        print(f"   units at work per 50 s: {at_work(units)}")
    da, db = {key(u): u for u in a}, {key(u): u for u in b}
    changes = []
    for k in set(da) | set(db):
        x, y = da.get(k), db.get(k)
        changes.append(((y["duration"] if y else 0) - (x["duration"] if x else 0), k,
                        x and x["duration"], y and y["duration"]))
    changes.sort(key=lambda c: -abs(c[0]))
    print("largest changes (B - A, s):")
    for d, k, x, y in changes[:25]:
        print(f"   {d:+7.1f}  {k[0]} {k[1]} {k[2]}  ({x} -> {y})")
    for name, units in (("A", a), ("B", b)):
        print(f"topple's targets in {name}:")
        for u in sorted((u for u in units if u["name"] == "topple" and u["duration"] > 0),
                        key=lambda u: u["start"]):
            parts = ", ".join(f"{s[0]} {s[1]['end'] - s[1]['start']:.1f}" for s in u["sections"] or [])
            print(f"   {u['target'].strip() or 'lib'}: start {u['start']:.1f}, {u['duration']:.1f} s"
                  + (f" ({parts})" if parts else ""))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

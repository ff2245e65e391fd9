"""`modc fmt` (format_text, also the LSP's formatting) on long chains: time per unit must not
grow with the chain (linear), measured side by side at n and 8n units. Not a test.

    python benchmarks/bench_fmt.py            # 1,000 and 8,000 units (the issue's 144 kB file)
    python benchmarks/bench_fmt.py --json

Each size is formatted --repeat times and the fastest run (process CPU time) counts, so other
load on the machine inflates neither. Target: per-unit time at 8,000 units within 1.5x of the
time at 1,000 (a quadratic formatter would show 8x), and 8,000 units in under 2 s.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def chain(n: int) -> str:
    return "robot a {\n    chain H1 - " + " - ".join(["L4(port=45deg)"] * n) + "\n}\n"


def best(text: str, repeat: int) -> float:
    from modc.syntax.format import format_text

    times = []
    for _ in range(repeat):
        t = time.process_time()
        out, errors = format_text(text, "bench.mod")
        times.append(time.process_time() - t)
        assert out is not None, errors
    return min(times)


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--small", type=int, default=1000)
    p.add_argument("--large", type=int, default=8000)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    best(chain(100), 1)  # warm: grammar tables loaded
    small, large = best(chain(a.small), a.repeat), best(chain(a.large), a.repeat)
    doc = {"units": [a.small, a.large], "bytes": [len(chain(a.small)), len(chain(a.large))],
           "seconds": [round(small, 3), round(large, 3)],
           "us_per_unit": [round(small / a.small * 1e6, 1), round(large / a.large * 1e6, 1)],
           "ratio_per_unit": round((large / a.large) / (small / a.small), 2)}
    if a.json:
        print(json.dumps(doc, indent=2))
    else:
        print(f"fmt {a.small:,} units ({doc['bytes'][0]:,} B): {small:.3f} s   {doc['us_per_unit'][0]} us/unit")
        print(f"fmt {a.large:,} units ({doc['bytes'][1]:,} B): {large:.3f} s   {doc['us_per_unit'][1]} us/unit")
        print(f"per-unit ratio large/small: {doc['ratio_per_unit']} (1.0 = linear)")


if __name__ == "__main__":
    main()

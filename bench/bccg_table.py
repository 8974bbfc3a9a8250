"""The BCCG summary table of docs/bem.md from a `bench/bem_peers.py` results.json:
per (N, boundary, p̄) asperity's BCCG on 2 and 1 threads, its Polonsky–Keer, and
ContactMechanics' CCG without restart, with iterations, the cost of an iteration in padded
FFT pairs (measured in the same run) and the ratios.

    python3 bench/bccg_table.py bench/out/results.json
"""
import json
import sys


def main(path):
    data = json.load(open(path))
    rows = {}
    for r in data["results"]:
        rows[(r["n"], r["boundary"], r["pressure"], r["code"])] = r
    keys = sorted({k[:3] for k in rows}, key=lambda k: (k[1], k[0], k[2]))
    print("| N | boundary | p̄ | BCCG 2 threads: s (it, pairs/it) | BCCG 1 thread: s (pairs/it) "
          "| PK 2 threads: s (it) | CM CCG w/o restart: s (it) | CM ÷ BCCG 2t | CM ÷ BCCG 1t |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n, boundary, p in keys:
        get = lambda code: rows.get((n, boundary, p, code))
        b2, b1, pk, cm = (get(c) for c in ("asperity-bccg-2t", "asperity-bccg-1t",
                                              "asperity-pk-2t", "cm-ccg"))
        if not (b2 and b1 and cm):
            continue
        pk_text = f"{pk['seconds']:.3f} ({pk['iterations']})" if pk else "—"
        print(f"| {n} | {boundary} | {p} | {b2['seconds']:.3f} ({b2['iterations']}, "
              f"{b2['iteration_in_pairs']:.2f}) | {b1['seconds']:.3f} "
              f"({b1['iteration_in_pairs']:.2f}) | {pk_text} | {cm['seconds']:.3f} "
              f"({cm['iterations']}) | {cm['seconds'] / b2['seconds']:.1f}× | "
              f"{cm['seconds'] / b1['seconds']:.1f}× |")
    env = data["environment"]
    print(f"\nMeasured {env['date']}, commit {env['asperity_commit'][:7]}, load average at the "
          f"start {env['loadavg'][0]:.2f}, {env['nproc']} cores; peers {env['peers']}.")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/out/results.json")

"""The BCCG summary table of docs/bem.md from a `bench/bem_peers.py` results.json:
per (N, boundary, p̄) asperity's BCCG on 2 and 1 threads, its Polonsky–Keer, and
ContactMechanics' CCG without restart, with iterations, the cost of an iteration in padded
FFT pairs (measured in the same run) and the ratios.

    python3 bench/bccg_table.py bench/out/results.json            # docs/bem.md's table
    python3 bench/bccg_table.py bench/out/results.json --readme   # the README's table
"""
import json
import sys


def padded_pairs(data):
    """The 2N×2N pair's seconds per (N, threads), from the run's `fft_pairs`."""
    return {(f["n"], f["threads"]): f["pair_seconds"] for f in data.get("fft_pairs", [])
            if f["boundary"] == "free"}


def padded(r, pairs):
    """The iteration in issue 10's unit, the 2N×2N pair measured in the same run, whatever
    the boundary."""
    pair = pairs.get((r["n"], r["threads"]))
    if pair is None or not r.get("iterations"):
        return "—"
    return f"{r['seconds'] / r['iterations'] / pair:.2f}"


def cases(data, codes):
    """Per case (N, boundary, p̄), in table order (free first, then by N and p̄): the case
    and the result of each of `codes` (None where that code has none)."""
    rows = {(r["n"], r["boundary"], r["pressure"], r["code"]): r for r in data["results"]}
    keys = sorted({k[:3] for k in rows}, key=lambda k: (k[1], k[0], k[2]))
    for n, boundary, p in keys:
        yield (n, boundary, p), [rows.get((n, boundary, p, code)) for code in codes]


def main(path):
    data = json.load(open(path))
    pairs = padded_pairs(data)
    print("| N | boundary | p̄ | BCCG 2 threads: s (it, pairs/it) | BCCG 1 thread: s (pairs/it) "
          "| PK 2 threads: s (it) | CM CCG w/o restart: s (it) | CM ÷ BCCG 2t | CM ÷ BCCG 1t "
          "| BCCG iteration in 2N×2N pairs, 2t / 1t |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    codes = ("asperity-bccg-2t", "asperity-bccg-1t", "asperity-pk-2t", "cm-ccg")
    for (n, boundary, p), (b2, b1, pk, cm) in cases(data, codes):
        if not (b2 and b1 and cm):
            continue
        pk_text = f"{pk['seconds']:.3f} ({pk['iterations']})" if pk else "—"
        print(f"| {n} | {boundary} | {p} | {b2['seconds']:.3f} ({b2['iterations']}, "
              f"{b2['iteration_in_pairs']:.2f}) | {b1['seconds']:.3f} "
              f"({b1['iteration_in_pairs']:.2f}) | {pk_text} | {cm['seconds']:.3f} "
              f"({cm['iterations']}) | {cm['seconds'] / b2['seconds']:.1f}× | "
              f"{cm['seconds'] / b1['seconds']:.1f}× | {padded(b2, pairs)} / {padded(b1, pairs)} |")
    env = data["environment"]
    print(f"\nMeasured {env['date']}, commit {env['asperity_commit'][:7]}, load average at the "
          f"start {env['loadavg'][0]:.2f}, {env['nproc']} cores; peers {env['peers']}.")


def readme(path):
    """The README's table: asperity's default solver against every peer, per case."""
    data = json.load(open(path))
    print("| N | boundary | p̄ | asperity 2 threads: s (iterations) | asperity 1 thread (s) "
          "| tamaas PK (s) | ContactMechanics PK (s) | ContactMechanics CCG w/o restart: "
          "s (iterations) | CCG ÷ asperity, 2 / 1 threads | tamaas ÷ asperity 2 threads |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    codes = ("asperity-bccg-2t", "asperity-bccg-1t", "tamaas", "contactmechanics", "cm-ccg")
    for (n, boundary, p), (b2, b1, tm, cm, ccg) in cases(data, codes):
        if not (b2 and b1 and tm and cm and ccg):
            continue
        print(f"| {n} | {boundary} | {p} | {b2['seconds']:.3f} ({b2['iterations']}) | "
              f"{b1['seconds']:.3f} | {tm['seconds']:.2f} | {cm['seconds']:.2f} | "
              f"{ccg['seconds']:.2f} ({ccg['iterations']}) | "
              f"{ccg['seconds'] / b2['seconds']:.1f}× / {ccg['seconds'] / b1['seconds']:.1f}× | "
              f"{tm['seconds'] / b2['seconds']:.0f}× |")


if __name__ == "__main__":
    path = sys.argv[1] if len(sys.argv) > 1 else "bench/out/results.json"
    (readme if "--readme" in sys.argv[2:] else main)(path)

#!/usr/bin/python3
"""Plot kinetic, strain and total energy from a Cairn history.csv.

usage: plot_history.py HISTORY.csv OUT.png [--title TEXT]
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("history")
    ap.add_argument("png")
    ap.add_argument("--title", default="")
    args = ap.parse_args()
    with open(args.history) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["time"]) * 1e3 for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for key, label in (("kinetic_energy", "kinetic"), ("strain_energy", "strain"), ("total_energy", "total")):
        ax.plot(t, [float(r[key]) for r in rows], label=label)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("energy (J per unit thickness)")
    ax.set_title(args.title)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)


if __name__ == "__main__":
    main()

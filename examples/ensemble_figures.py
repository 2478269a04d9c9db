#!/usr/bin/python3
"""Charts of an ensemble written by `frictherm ensemble` (coupling/ensemble.hpp): hot spots per
member, their size and peak-temperature distributions, and, when the members had a reactive
thermal-only continuation, their fates and times to runaway.

  ensemble_figures.py ENSEMBLE.h5 [-o PREFIX]

Writes PREFIX_hotspots.png (four panels) and prints the summary attributes. Reads the file through
the frictherm Python package (python/frictherm). Uses the Debian packages python3-h5py,
python3-matplotlib and python3-numpy; runs headless.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import frictherm  # noqa: E402

FATES = {0: "undecided", 1: "dying", 2: "runaway"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ensemble")
    ap.add_argument("-o", "--prefix", default=None)
    a = ap.parse_args()
    prefix = a.prefix or os.path.splitext(a.ensemble)[0]
    with frictherm.open(a.ensemble) as ens:
        if not isinstance(ens, frictherm.Ensemble):
            raise SystemExit("ensemble_figures.py: %s is a run, not an ensemble file" % a.ensemble)
        attrs = ens.summary
        m, h = ens.members, ens.hotspots
    for k in sorted(attrs):
        print("%-26s %s" % (k, "undefined (no hot spot with a known fate)" if attrs[k] is None else attrs[k]))
    fig, ax = plt.subplots(2, 2, figsize=(9, 7))
    ok = m["status"] < 2
    counts = m["hotspots"][ok]
    ax[0, 0].hist(counts, bins=np.arange(counts.max() + 2) - 0.5 if counts.size else 1, color="C0")
    ax[0, 0].set_xlabel("hot spots per member")
    ax[0, 0].set_ylabel("members")
    ax[0, 0].set_title("%d members, %.2f ± %.2f hot spots each" % (ok.sum(), attrs.get("hotspots_per_member_mean", 0),
                                                                  attrs.get("hotspots_per_member_std", 0)), fontsize=9)
    if len(h):
        ax[0, 1].hist(1e6 * h["equivalent_diameter"], bins=20, color="C1")
        ax[1, 0].hist(h["peak_temperature"], bins=20, color="C3")
    ax[0, 1].set_xlabel("equivalent diameter at peak (µm)")
    ax[0, 1].set_ylabel("hot spots")
    ax[1, 0].set_xlabel("peak temperature (K)")
    ax[1, 0].set_ylabel("hot spots")
    fates = h["fate"].astype(int) if len(h) else np.array([], int)
    known = fates > 0
    if known.any():
        d = 1e6 * h["equivalent_diameter"]
        for code, colour in ((1, "C0"), (2, "C3")):
            sel = fates == code
            ax[1, 1].scatter(d[sel], h["peak_temperature"][sel], s=12, color=colour, label=FATES[code])
        ax[1, 1].set_xlabel("equivalent diameter (µm)")
        ax[1, 1].set_ylabel("peak temperature (K)")
        ax[1, 1].legend(fontsize=8)
        ax[1, 1].set_title("critical fraction %.3f (%d runaway of %d decided)" % (
            ens.critical_fraction, (fates == 2).sum(), known.sum()), fontsize=9)
    else:
        ax[1, 1].text(0.5, 0.5, "no fates: the members had no\nthermal-only continuation", ha="center", va="center")
        ax[1, 1].set_axis_off()
    fig.suptitle("ensemble over %s = %d ... %d" % (attrs.get("seed_key", "seed"), m["seed"].min(), m["seed"].max()))
    fig.tight_layout()
    out = prefix + "_hotspots.png"
    fig.savefig(out, dpi=130)
    print("wrote", out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The packing fraction of the 3D deposition generator against the published value:
``taichi-sls bench packing3d [--seeds 6] [--out renders]``.

Deposits ``--spheres`` equal spheres over a periodic (x, z) square of ``--side`` diameters,
once per seed, and reads each bed's bulk fraction (the core window 2 diameters clear of the
plate and of the mean top; config/packing.py) beside Visscher & Bolsterli's 0.58 for random
sequential deposition with rolling; then the same with side walls (the domain of a case) and
with a log-normal spread of 0.2. Writes bed3d_packing.csv (one row per bed) and
bed3d_packing.png: a slice of the first bed through its middle, and the fraction in slabs a
quarter diameter thick against the height, for every periodic bed of equal spheres.
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

import numpy as np

from taichi_sls.config.deposition import deposit, lognormal_diameters
from taichi_sls.config.packing import packing_fractions, slab_volume
from taichi_sls.io.atomic import atomic_path

VISSCHER_BOLSTERLI = 0.58  # Nature 239, 504 (1972): sequential deposition with rolling, 3D
RLP, RCP = 0.55, 0.64  # random loose and random close packing of equal spheres
VARIANTS = (("periodic", 0.0), ("walls", 0.0), ("periodic", 0.2))


def deposit_bed(n: int, side: float, seed: int, lateral: str, spread: float):
    """n spheres of median diameter 1 over side x side: (centres, radii, seconds)."""
    rng = np.random.default_rng(seed)
    r = lognormal_diameters(rng, n, 1.0, spread) / 2
    t0 = time.perf_counter()
    c = deposit(r, [(0.0, side), (0.0, side)], rng, lateral=lateral)  # type: ignore[arg-type]
    return c, r, time.perf_counter() - t0


def add_parser(sub: argparse._SubParsersAction) -> None:
    ap = sub.add_parser("packing3d", help="the 3D bed generator's packing fraction, per seed")
    ap.add_argument("--out", default="renders", help="folder for bed3d_packing.csv and .png")
    ap.add_argument("--seeds", type=int, default=6, help="beds per variant (seeds 0..n-1)")
    ap.add_argument("--spheres", type=int, default=2000, help="spheres per bed")
    ap.add_argument("--side", type=float, default=12.0, help="bed side, in diameters")
    ap.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows, beds = [], []
    for lateral, spread in VARIANTS:
        for seed in range(args.seeds):
            c, r, wall = deposit_bed(args.spheres, args.side, seed, lateral, spread)
            rng = (0.0, args.side)
            pf = packing_fractions(c, r, [rng, rng], lateral == "periodic")
            rows.append(
                {
                    "lateral": lateral,
                    "spread": spread,
                    "seed": seed,
                    "spheres": len(r),
                    "bulk": round(pf["bulk"], 5),
                    "envelope": round(pf["envelope"], 5),
                    "mean_top_d": round(pf["mean_top"], 3),
                    "seconds": round(wall, 2),
                }
            )
            print(", ".join(f"{k} {v}" for k, v in rows[-1].items()), flush=True)
            if lateral == "periodic" and spread == 0.0:
                beds.append((c, r, pf))
    with atomic_path(out / "bed3d_packing.csv") as path, path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for lateral, spread in VARIANTS:
        bulk = [row["bulk"] for row in rows if (row["lateral"], row["spread"]) == (lateral, spread)]
        print(
            f"{lateral}, spread {spread}: bulk {min(bulk):.4f}-{max(bulk):.4f} (Visscher & "
            f"Bolsterli {VISSCHER_BOLSTERLI})"
        )
    plot(out / "bed3d_packing.png", beds, args.side)
    return 0


def plot(path: Path, beds: list, side: float) -> None:
    """A slice through the first bed (the discs the spheres cut from the plane z = side / 2)
    and every bed's fraction in slabs against the height."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.6), width_ratios=(1.6, 1))
    c, r, pf = beds[0]
    dz = c[:, 2] - side / 2
    cut = np.abs(dz) < r
    discs = [
        Circle((x, y), np.sqrt(rr * rr - d * d))
        for x, y, rr, d in zip(c[cut, 0], c[cut, 1], r[cut], dz[cut], strict=True)
    ]
    ax.add_collection(PatchCollection(discs, facecolor="#c9a66b", edgecolor="#5a4320", lw=0.4))
    for y in pf["core_y"]:
        ax.axhline(y, color="tab:blue", ls="--", lw=1)
    ax.set(xlim=(0, side), ylim=(0, float(np.max(c[:, 1] + r)) + 0.3), aspect="equal")
    ax.set(
        xlabel="x / d",
        ylabel="y / d",
        title=f"slice z = {side / 2:g} d of seed 0 (periodic in x, z; dashed: the core window)",
    )
    edges = np.arange(0.0, float(np.max(c[:, 1])) + 1.0, 0.25)
    for k, (c, r, _) in enumerate(beds):
        frac = [np.sum(slab_volume(c[:, 1], r, a, a + 0.25)) / (0.25 * side**2) for a in edges]
        bx.plot(
            frac,
            edges + 0.125,
            lw=0.8,
            label=f"seeds 0-{len(beds) - 1}" if k == 0 else None,
            color="0.3",
            alpha=0.7,
        )
    bulk = [pf["bulk"] for _, _, pf in beds]
    bx.axvline(VISSCHER_BOLSTERLI, color="tab:red", label="Visscher & Bolsterli 1972: 0.58")
    bx.axvspan(RLP, RCP, color="tab:green", alpha=0.08, label="random loose-close 0.55-0.64")
    for y in beds[0][2]["core_y"]:
        bx.axhline(y, color="tab:blue", ls="--", lw=1)
    bx.set(
        xlim=(0.3, 0.75),
        xlabel="packing fraction in slabs of d / 4",
        ylabel="y / d",
        title=f"core: {min(bulk):.3f}-{max(bulk):.3f} ({len(r)} spheres)",
    )
    bx.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)

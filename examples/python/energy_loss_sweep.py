#!/usr/bin/python3
"""The energy-loss table of seed 000 Sec. 3.2 as a Python loop: two blocks collide (seed 000
Sec. 3.1) under FLIP, FMPM(k) and XPIC(k); the loss of kinetic + strain energy at the end is the
method's numerical dissipation. Many small runs in one process, each in a temporary folder.

    /usr/bin/python3 examples/python/energy_loss_sweep.py [--orders 1,2,4,8] [--plot loss.png]

The set-up is verification/two_blocks's (tools/verification_common/two_blocks_setup.py): CPDI,
1 mm cells, 2 x 2 particles per cell, CFL 0.2, USL; its README states the losses this prints
(FMPM(1) 33.2 %, FMPM(2) 5.15 %, FMPM(8) 0.52 %, FLIP 1.69 %). docs/python.md, "Sweeps".
"""
import argparse
import math

import cairn

LAMBDA, G, RHO = 7.29766e6, 3.7594e6, 1500.0   # Pa, Pa, kg/m^3 (seed 000 Sec. 3.1; rho our choice)
V0 = 8.165                                      # m/s, 10 % of the bar wave speed
L, W, H = 0.050, 0.020, 1e-3                    # block length and height, cell size (m)
MARGIN, HEIGHT, GAP = 0.010, 0.040, 4 * H


def end_time():
    """Contact, the wave's return through a block, the rebound's reopening of the gap, 0.3 ms
    (verification/two_blocks/README.md, "Timing"; CPDI reaches one cell)."""
    c_bar = math.sqrt(G * (3 * LAMBDA + 2 * G) / (LAMBDA + G) / RHO)
    return (GAP - 2 * H) / (2 * V0) + 2 * L / c_bar + H / V0 + 0.3e-3


def two_blocks(update, k):
    y0 = 0.5 * (HEIGHT - W)
    method = {"shape": "cpdi", "update": update, "stress_update": "usl"}
    if update != "flip":
        method["order"] = k
    block = {"material": "rubber", "particles_per_cell": 2}
    return {
        "simulation": {"dimension": 2, "mode": "plane_strain", "end_time": end_time(), "cfl": 0.2},
        "grid": {"origin": [0.0, 0.0], "extent": [2 * MARGIN + 2 * L + GAP, HEIGHT], "cell_size": H},
        "method": method,
        "material": [{"name": "rubber", "model": "neo_hookean", "form": "j_squared", "density": RHO,
                      "lambda": LAMBDA, "shear_modulus": G}],
        "body": [
            dict(block, name="left", velocity=[V0, 0.0],
                 shape={"box": {"min": [MARGIN, y0], "max": [MARGIN + L, y0 + W]}}),
            dict(block, name="right", velocity=[-V0, 0.0],
                 shape={"box": {"min": [MARGIN + L + GAP, y0], "max": [MARGIN + 2 * L + GAP, y0 + W]}}),
        ],
        # No snapshots or checkpoints: the history is all the table needs.
        "output": {"every": 0.0, "history_every": end_time() / 10, "checkpoints": False},
    }


def energy_loss(update, k=1):
    """Percent of the initial kinetic + strain energy lost by the end."""
    with cairn.Simulation.from_dict(two_blocks(update, k), name=f"{update}{k}", output=False) as sim:
        sim.run(progress=False)
        h = sim.history(as_pandas=False)
    e = h["kinetic_energy"] + h["strain_energy"]
    return 100.0 * (1.0 - e[-1] / e[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--orders", default="1,2,4,8", help="FMPM/XPIC orders k (comma-separated)")
    parser.add_argument("--plot", help="write the loss against k to this picture (matplotlib)")
    args = parser.parse_args()
    orders = [int(k) for k in args.orders.split(",")]
    flip = energy_loss("flip")
    table = {update: {k: energy_loss(update, k) for k in orders} for update in ("fmpm", "xpic")}
    print("| method | " + " | ".join(f"k = {k}" for k in orders) + " |")
    print("|---|" + "---|" * len(orders))
    for update, losses in table.items():
        print(f"| {update.upper()}(k) | " + " | ".join(f"{losses[k]:.3f} %" for k in orders) + " |")
    print(f"| FLIP | {flip:.3f} % |")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 3.5))
        for update, losses in table.items():
            ax.semilogy(orders, [losses[k] for k in orders], "o-", label=f"{update.upper()}(k)")
        ax.axhline(flip, color="k", ls="--", label="FLIP")
        ax.set_xlabel("order k")
        ax.set_ylabel("energy loss (%)")
        ax.set_title("two blocks, CPDI, 1 mm, CFL 0.2 (seed 000 Sec. 3.2)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
    return table, flip


if __name__ == "__main__":
    main()

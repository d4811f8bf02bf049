#!/usr/bin/env python3
"""A parameter study over conform.run: the skin's Young's modulus against the tear's opening.

Runs the tear-opening scene (no pictures) for several moduli, prints a table of the physical
and geometric openings and writes parameter_study.png into OUT (default:
results/python-study). A sweep of the same grid: conform.sweep("tear-opening",
grid={"material.youngs_modulus": [...]}).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/parameter_study.py
"""
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import conform  # noqa: E402

MODULI = [0.2e6, 0.42e6, 0.85e6, 1.5e6]  # Pa; 0.42 MPa (under 30) and 0.85 MPa (over 30)
STEPS = 90  # the stroke ends at 1.0 s; half a second of settling


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "results/python-study")
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for e in MODULI:
        m = conform.run("tear-opening", steps=STEPS, render=False,
                        set={"material.youngs_modulus": e})["metrics"]
        rows.append((e, m["physics"]["max_opening"], m["geometric"]["max_opening"],
                     m["physics"]["profile_r2"]))
        print(f"E = {e / 1e6:5.2f} MPa: physics {rows[-1][1] * 1e3:6.3f} mm, "
              f"geometric {rows[-1][2] * 1e3:6.3f} mm, profile R2 {rows[-1][3]:.4f}")
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot([r[0] / 1e6 for r in rows], [r[1] * 1e3 for r in rows], "o-", label="membrane")
    ax.plot([r[0] / 1e6 for r in rows], [r[2] * 1e3 for r in rows], "s--", label="geometric")
    ax.set(xlabel="Young's modulus (MPa)", ylabel="largest opening (mm)",
           title=f"tear-opening after {STEPS} steps")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "parameter_study.png", dpi=110)
    print(f"plot: {out / 'parameter_study.png'}")


if __name__ == "__main__":
    main()

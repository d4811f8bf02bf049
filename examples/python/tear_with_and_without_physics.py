#!/usr/bin/env python3
"""The arm's forearm torn by a scalpel stroke, opened by physics and geometrically.

1. The `tear-opening` scene: the same stroke on the membrane-skinned soft arm (the
   pre-stressed skin pulls the lips apart) and on the posed mesh alone, opened by
   Algorithm 2 step 6 (geometric). Its profiles.csv holds both gap-width profiles.
2. The same stroke through the library from Python: a World, the arm, Body.tear, steps, and
   the width between the lips (Body.tear_openings) as the skin settles.

Writes tear_openings.png (and the scene's results) into OUT (default: results/python-tear).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/tear_with_and_without_physics.py
"""
import csv
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import conform  # noqa: E402


def scene_profiles(out):
    """Runs tear-opening (membrane and geometric) and returns its last profiles."""
    summary = conform.run("tear-opening", out=out / "tear-opening", render=False)
    with open(out / "tear-opening" / "profiles.csv") as f:
        rows = list(csv.DictReader(f))
    last_phys = [k for k in rows[0] if k.startswith("physics_")][-1]
    last_geom = [k for k in rows[0] if k.startswith("geometric_")][-1]
    s = np.array([float(r["s"]) for r in rows])
    phys = np.array([float(r[last_phys]) for r in rows])
    geom = np.array([float(r[last_geom]) for r in rows])
    return summary, s, phys, geom, last_phys.split("_")[1]


def live_tear(seconds=1.5, dt=1 / 60):
    """The same stroke on a live membrane arm; the largest opening after each step."""
    world = conform.World()
    arm = world.add_arm()
    world.step(dt)
    u = np.linspace(0, 1, 40)[:, None]
    p = (1 - u) * np.array([0, 0.0023, 0.3712]) + u * np.array([0, 0.0023, 0.4912])
    mass = arm.total_mass
    extended = arm.tear(p + [0.09, 0, 0], p + [0.005, 0, 0], smooth_lips=True)
    t, widest = [], []
    for i in range(int(seconds / dt)):
        world.step(dt)
        t.append((i + 1) * dt)
        widest.append(arm.tear_openings.max())
    assert abs(arm.total_mass - mass) <= 1e-9 * mass
    return extended, np.array(t), np.array(widest), arm.tear_openings


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "results/python-tear")
    out.mkdir(parents=True, exist_ok=True)
    summary, s, phys, geom, when = scene_profiles(out)
    extended, t, widest, final = live_tear()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.plot(s, phys * 1e3, label="membrane (physics)")
    left.plot(s, geom * 1e3, "--", label="geometric (Algorithm 2 step 6)")
    left.plot(np.linspace(0, 1, len(final)), final * 1e3, ":", label="live Body.tear, path points")
    left.set(title=f"tear-opening scene at t = {when}", xlabel="position along the tear",
             ylabel="opening (mm)")
    left.legend()
    right.plot(t, widest * 1e3)
    right.set(title=f"live Body.tear from Python ({extended} samples extended it)",
              xlabel="time after the tear (s)", ylabel="largest opening (mm)")
    fig.tight_layout()
    fig.savefig(out / "tear_openings.png", dpi=110)
    m = summary["metrics"]
    print(f"scene: physics max opening {m['physics']['max_opening'] * 1e3:.2f} mm, "
          f"geometric {m['geometric']['max_opening'] * 1e3:.2f} mm")
    print(f"live:  largest opening {final.max() * 1e3:.2f} mm after {t[-1]:.2f} s")
    print(f"plot:  {out / 'tear_openings.png'}")


if __name__ == "__main__":
    main()

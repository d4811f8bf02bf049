#!/usr/bin/env python3
"""A Python loop of 1000 World.step() calls on the arm against the same loop in C++.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_step_loop.py [build]

Runs build/benchmarks/step_loop_bench (the C++ loop, median of 3) and the same loop through
the `conform` module (median of 3), and prints both and their ratio. Also times a Python loop
of 1000 cheap binding calls (Body.vertex_count), the binding's own cost per call.
"""
import json
import pathlib
import statistics
import subprocess
import sys
import time

import conform

STEPS = 1000


def python_loop():
    world = conform.World(gravity=(0, -9.81, 0), ground=-0.5)
    world.add_arm(resolution=1)
    start = time.perf_counter()
    for _ in range(STEPS):
        world.step(1 / 60)
    return time.perf_counter() - start


def call_overhead():
    world = conform.World()
    body = world.add_arm()
    start = time.perf_counter()
    for _ in range(STEPS):
        body.vertex_count
    return (time.perf_counter() - start) / STEPS


def cxx_loop(build):
    exe = pathlib.Path(build) / "benchmarks" / "step_loop_bench"
    out = subprocess.run([str(exe), "--benchmark_format=json",
                          "--benchmark_filter=BM_ArmStepLoop"],
                         check=True, capture_output=True, text=True).stdout
    runs = [b for b in json.loads(out)["benchmarks"] if b.get("aggregate_name") == "median"]
    return runs[0]["real_time"] / 1e3  # ms -> s


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    cxx = cxx_loop(build)
    py = statistics.median(python_loop() for _ in range(3))
    call = call_overhead()
    print(f"C++    loop of {STEPS} steps: {cxx:.3f} s ({cxx / STEPS * 1e3:.3f} ms/step)")
    print(f"Python loop of {STEPS} steps: {py:.3f} s ({py / STEPS * 1e3:.3f} ms/step)")
    print(f"ratio Python / C++: {py / cxx:.4f}")
    print(f"one cheap binding call: {call * 1e6:.2f} us")


if __name__ == "__main__":
    main()

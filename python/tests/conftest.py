"""Shared fixtures of the conform module's tests.

The module is found through PYTHONPATH (ctest sets it to <build>/python); the `conform`
command for the comparison with the CLI through CONFORM_EXE (ctest sets it), else beside it.
"""
import os
import pathlib

import numpy as np
import pytest

import conform


@pytest.fixture(scope="session")
def conform_exe():
    exe = os.environ.get("CONFORM_EXE")
    if not exe:
        exe = str(pathlib.Path(conform.__file__).resolve().parent.parent / "scenes" / "conform")
    if not os.access(exe, os.X_OK):
        pytest.fail(f"the conform command is not at {exe} (set CONFORM_EXE)")
    return exe


@pytest.fixture
def world():
    return conform.World(gravity=(0, -9.81, 0), ground=-0.5)


@pytest.fixture
def arm(world):
    body = world.add_arm(resolution=1)
    world.step(1 / 60)
    return body


def forearm_stroke(samples=20):
    """The tear-opening scene's stroke along the forearm: blade ends (N, 3) each."""
    u = np.linspace(0.0, 1.0, samples)[:, None]
    p = (1 - u) * np.array([0, 0.0023, 0.3712]) + u * np.array([0, 0.0023, 0.4912])
    return p + np.array([0.09, 0, 0]), p + np.array([0.005, 0, 0])

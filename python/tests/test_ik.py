"""The arm IK from Python: batched equals scalar, both match forward kinematics."""
import numpy as np
import pytest

from conform import ik


def targets(n=200, seed=7):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    r = rng.uniform(0.08, 0.54, size=n)  # inside the reach (0.05, 0.55) of the default arm
    return d * r[:, None], rng.uniform(-np.pi, np.pi, size=n)


def test_scalar_solution_matches_forward_kinematics():
    arm = ik.Arm()
    s = ik.solve((0.1, -0.2, 0.3), 0.3, arm)
    assert s["status"] == 0 and s["status_text"] == "ok"
    elbow, wrist = ik.forward_kinematics(s["qs"], s["qe"], arm)
    assert np.allclose(wrist, (0.1, -0.2, 0.3), atol=1e-12)
    assert np.allclose(elbow, s["elbow"], atol=1e-12)
    assert np.linalg.norm(elbow) == pytest.approx(arm.upper, abs=1e-12)


def test_batch_equals_scalar():
    p, phi = targets()
    b = ik.solve_batch(p, phi)
    assert b["qs"].shape == (len(p), 4) and b["elbow"].shape == (len(p), 3)
    for i in range(len(p)):
        s = ik.solve(p[i], phi[i])
        assert b["status"][i] == s["status"]
        assert np.allclose(b["qs"][i], s["qs"], atol=1e-12, rtol=0)
        assert np.allclose(b["qe"][i], s["qe"][:2], atol=1e-12, rtol=0)
        assert np.allclose(b["elbow"][i], s["elbow"], atol=1e-12, rtol=0)


def test_batch_matches_forward_kinematics():
    p, phi = targets(1000, seed=3)
    b = ik.solve_batch(p, phi, threads=1)
    assert (b["status"] == 0).all()
    elbow, wrist = ik.forward_kinematics_batch(b["qs"], b["qe"])
    assert np.abs(wrist - p).max() < 1e-12
    assert np.abs(elbow - b["elbow"]).max() < 1e-12


def test_unreachable_target_is_clamped_in_the_status():
    s = ik.solve((0, 0, 2.0), 0.0)
    assert "clamped_outer" in s["status_text"]
    b = ik.solve_batch(np.array([[0, 0, 2.0]]), 0.0)
    assert b["status"][0] == s["status"]


def test_batch_input_errors():
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        ik.solve_batch(np.zeros((4, 2)), 0.0)
    with pytest.raises(ValueError, match="swivel"):
        ik.solve_batch(np.zeros((4, 3)), np.zeros(3))

"""Pose sources from Python: keyframes on the arm, a model file's animation."""
import os

import numpy as np
import pytest

import conform

HUESITOS = "/usr/share/assimp/models/FBX/huesitos.fbx"  # Debian's assimp-testmodels


def test_keyframes_bend_the_elbow(world):
    arm = world.add_arm()
    c, s = np.cos(0.5), np.sin(0.5)  # 1 rad about x at t = 1 s
    arm.set_keyframes([0.0, 1.0], [{}, {"elbow": (c, s, 0, 0)}])
    for _ in range(70):  # past the last key, which then holds
        world.step(1 / 60)
    tip = arm.target(arm.vertex_count - 1)
    # The finger tips (0, 0, 0.63) turned by 1 rad about the elbow at (0, 0, 0.30).
    assert np.allclose(tip, [0, -0.33 * np.sin(1.0), 0.30 + 0.33 * np.cos(1.0)], atol=1e-3)


def test_pose_errors(world):
    arm = world.add_arm()
    with pytest.raises(ValueError, match="no joint named 'knee'"):
        arm.set_pose({"knee": (1, 0, 0, 0)})
    with pytest.raises(IndexError, match=r"joint 7 out of range \[0, 3\)"):
        arm.set_pose({7: (1, 0, 0, 0)})
    with pytest.raises(ValueError, match="quaternion"):
        arm.set_pose({0: (0, 0, 0, 0)})
    with pytest.raises(IndexError, match="animation 0 out of range"):
        arm.play(0)


@pytest.mark.skipif(not os.path.exists(HUESITOS), reason="assimp-testmodels is not installed")
def test_model_file_plays_its_animation_in_metres(world):
    body = world.add_model(HUESITOS)
    assert body.animations == ["Armature|Action"]
    rest = np.array(body.rest_positions)
    assert 0.05 < np.ptp(rest, axis=0).max() < 5  # brought to metres
    m0 = body.total_mass
    body.play("Armature|Action")
    before = np.array(body.positions)
    for _ in range(30):
        world.step(1 / 60)
    assert np.abs(body.positions - before).max() > 0.01
    assert abs(body.total_mass - m0) <= 1e-9 * m0

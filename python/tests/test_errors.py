"""Library exceptions reach Python with the library's message."""
import numpy as np
import pytest

import conform


def test_invalid_material_is_a_value_error_with_the_library_message(world):
    m = conform.Material()
    m.pretension = 1.5
    with pytest.raises(ValueError) as e:
        world.add_arm(material=m)
    assert str(e.value) == "SkinnedSoftBody: material pretension = 1.5 is out of range ([0, 1))"


def test_invalid_arm_resolution(world):
    with pytest.raises(ValueError, match="resolution"):
        world.add_arm(resolution=0)


def test_unreadable_model_is_a_model_import_error(world, tmp_path):
    missing = tmp_path / "missing.fbx"
    with pytest.raises(conform.ModelImportError) as e:
        world.add_model(str(missing))
    assert str(e.value).startswith(str(missing) + ": ")
    assert isinstance(e.value, RuntimeError)


def test_non_finite_tear_sample(arm):
    arm.begin_tear()
    with pytest.raises(ValueError, match="finite"):
        arm.tear_advance((np.nan, 0, 0.4), (0, 0, 0.4))


def test_bad_step_arguments(world):
    with pytest.raises(ValueError, match="dt = -1"):
        world.step(-1.0)


def test_non_finite_state_is_raised_out_of_step():
    # Gravity near float's largest value: within 70 steps a position overflows to inf.
    world = conform.World(gravity=(0, -3e38, 0), ground=None)
    arm = world.add_arm()
    arm.cut(point=(0, 0, 0.42), normal=(0, 0, 1))
    arm.release(arm.piece_of(arm.vertex_count - 1))
    with pytest.raises(conform.NonFiniteState) as e:
        for _ in range(200):
            world.step(1 / 60)
    assert isinstance(e.value, RuntimeError)
    assert str(e.value).startswith("the simulation went non-finite at substep ")


def test_stale_piece_id(arm):
    stale = (arm.piece_ids()[0][0], 12345)
    assert not arm.piece_valid(stale)
    with pytest.raises(ValueError):
        arm.release(stale)

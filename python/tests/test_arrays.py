"""Arrays: zero-copy read-only views where promised, copies elsewhere, and what a topology
change does to a view (the edit refuses to run while one is alive: BufferError)."""
import gc

import numpy as np
import pytest

from conftest import forearm_stroke

VIEWS = ["positions", "rest_positions", "faces", "bone_ids", "bone_weights"]
COPIES = ["velocities", "targets", "normals", "masses", "kinematic", "detached", "piece_slots",
          "face_kinds", "face_ops"]


@pytest.mark.parametrize("name", VIEWS)
def test_views_share_the_body_storage_and_are_read_only(arm, name):
    a, b = getattr(arm, name), getattr(arm, name)
    assert not a.flags.owndata and not a.flags.writeable
    assert np.shares_memory(a, b)
    assert type(a.base).__name__ == "_ViewBase"
    with pytest.raises(ValueError):
        a[0, 0] = 1
    assert arm.live_views == 2


@pytest.mark.parametrize("name", COPIES)
def test_copies_are_new_arrays(arm, name):
    a, b = getattr(arm, name), getattr(arm, name)
    assert a.flags.owndata and not np.shares_memory(a, b)
    assert len(a) in (arm.vertex_count, arm.face_count)


def test_a_view_keeps_the_world_alive(world):
    body = world.add_arm()
    p = body.positions
    del body, world
    gc.collect()
    assert p.shape == (2562, 3) and np.isfinite(p).all()


def test_positions_view_is_refreshed_in_place_by_a_read(world, arm):
    arm.set_arm_pose(qs=(1, 0, 0, 0), qe=(np.cos(0.4), np.sin(0.4), 0, 0))
    p = arm.positions
    old = p.copy()
    world.step(1 / 60)
    assert np.array_equal(p, old)  # not synced yet
    q = arm.positions  # syncs into the same storage
    assert np.shares_memory(p, q) and not np.array_equal(p, old)


@pytest.mark.parametrize("edit", ["cut", "tear", "drill"])
def test_an_edit_refuses_to_run_under_a_live_view(arm, edit):
    faces = arm.faces
    column = arm.positions[:, 2]  # a derived view counts too
    v0, f0 = arm.vertex_count, arm.face_count
    a, b = forearm_stroke()
    run = {
        "cut": lambda: arm.cut(point=(0, 0, 0.42), normal=(0, 0, 1)),
        "tear": lambda: arm.tear(a, b),
        "drill": lambda: arm.drill(tip=(0.1, 0, 0.15), base=(-0.1, 0, 0.15), radius=0.012),
    }[edit]
    with pytest.raises(BufferError, match="zero-copy array view"):
        run()
    assert (arm.vertex_count, arm.face_count) == (v0, f0)  # nothing changed
    assert faces.shape == (f0, 3) and column.shape == (v0,)
    kept = np.array(faces)  # a copy survives the edit
    del faces, column
    gc.collect()
    assert arm.live_views == 0
    run()
    assert arm.topology_version > 0 and kept.shape == (f0, 3)
    assert arm.faces.shape[0] != f0 or arm.vertex_count != v0

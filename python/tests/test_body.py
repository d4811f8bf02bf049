"""A live skinned soft body: cut, tear and drill from Python, mass conserved, piece events."""
import numpy as np
import pytest

import conform
from conftest import forearm_stroke


def rel(a, b):
    return abs(a - b) / abs(b)


def test_arm_steps_and_follows_its_pose(world, arm):
    assert arm.vertex_count == 2562 and arm.face_count == 5120 and arm.piece_count == 1
    assert arm.joint_names == ["shoulder", "elbow", "wrist"]
    for _ in range(5):
        world.step(1 / 60)
    assert world.substeps == 6 and world.time == pytest.approx(6 / 60, rel=1e-6)
    offsets = np.linalg.norm(arm.positions - arm.targets, axis=1)
    assert offsets.max() < 0.01  # the membrane keeps the skin on its skinned targets
    # A flexed elbow moves the hand's targets.
    hand = arm.vertex_count - 1
    before = arm.target(hand)
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    arm.set_arm_pose(qs=(1, 0, 0, 0), qe=(c, s, 0, 0))
    world.step(1 / 60)
    assert np.linalg.norm(arm.target(hand) - before) > 0.05


def test_live_cut_conserves_mass_and_reports_the_new_piece(world, arm):
    events = []
    arm.on_piece_event(events.append)
    m0, p0 = arm.total_mass, arm.momentum
    r = arm.cut(point=(0, 0, 0.42), normal=(0, 0, 1))
    assert r["status"] == "cut" and r["new_pieces"] == 1 and arm.piece_count == 2
    assert rel(arm.total_mass, m0) < 1e-9
    assert np.linalg.norm(arm.momentum - p0) <= 1e-9 * max(arm.momentum_scale, 1e-12)
    assert [e.kind for e in events] == [conform.Body.PieceEventKind.created]
    assert events[0].parent == arm.piece_ids()[0]
    assert [e.piece for e in arm.events()] == [events[0].piece]
    for _ in range(3):
        world.step(1 / 60)
    assert rel(arm.total_mass, m0) < 1e-9
    slots = arm.piece_slots
    assert set(np.unique(slots)) == {p[0] for p in arm.piece_ids()}
    assert arm.cut(point=(0, 0, 5), normal=(0, 0, 1))["status"] == "missed"


def test_live_tear_stroke_conserves_mass_and_opens(world, arm):
    m0, v0 = arm.total_mass, arm.vertex_count
    a, b = forearm_stroke()
    extended = arm.tear(a, b, smooth_lips=True)
    assert extended >= 15
    assert arm.vertex_count > v0 and rel(arm.total_mass, m0) < 1e-9
    left, right = arm.tear_borders
    assert left[0] == right[0] and left[-1] == right[-1]
    assert list(arm.tear_tips) == [left[0], left[-1]]
    assert arm.tear_length == pytest.approx(0.12, rel=0.1)
    for _ in range(20):
        world.step(1 / 60)
    assert rel(arm.total_mass, m0) < 1e-9
    assert arm.tear_openings.max() > 1e-3  # the pre-stressed skin pulls the lips apart


def test_tear_sample_by_sample_equals_the_stroke(world):
    one = world.add_arm()
    two = world.add_arm()
    a, b = forearm_stroke(12)
    n = one.tear(a, b)
    two.begin_tear()
    m = sum(two.tear_advance(a[i], b[i], t=float(i)) for i in range(len(a)))
    assert n == m
    assert np.array_equal(one.faces, two.faces)
    assert np.array_equal(one.positions, two.positions)


def test_live_drill_conserves_mass(world, arm):
    m0 = arm.total_mass
    r = arm.drill(tip=(0.1, 0.0031, 0.1512), base=(-0.1, 0.0031, 0.1512), radius=0.012, tube=True)
    assert r["holes"] == 2 and r["tubes"] == 1
    assert rel(arm.total_mass, m0) < 1e-9
    assert arm.detached_count > 0 and arm.detached.sum() == arm.detached_count
    assert (arm.face_kinds == 2).sum() == r["tube_faces"]
    world.step(1 / 60)
    assert rel(arm.total_mass, m0) < 1e-9


def test_released_piece_falls(world, arm):
    arm.cut(point=(0, 0, 0.42), normal=(0, 0, 1))
    hand = arm.piece_of(arm.vertex_count - 1)
    arm.release(hand)
    assert arm.piece_released(hand)
    y0 = arm.position(arm.vertex_count - 1)[1]
    for _ in range(20):
        world.step(1 / 60)
    assert arm.position(arm.vertex_count - 1)[1] < y0 - 0.05


def test_material_fields_reach_the_body(world):
    m = conform.Material()
    m.skin.youngs_modulus = 0.85e6
    m.skin.toughness = 5000.0
    m.skin.law = conform.SkinMaterial.Law.neo_hookean
    m.pretension = 0.1
    body = world.add_arm(material=m)
    assert body.material.skin.youngs_modulus == 0.85e6
    assert body.material.skin.toughness == 5000.0
    assert body.material.skin.law == conform.SkinMaterial.Law.neo_hookean
    links = conform.Material()
    links.model = conform.MaterialModel.bullet_links
    b2 = world.add_arm(material=links)
    world.step(1 / 60)
    assert b2.material.model == conform.MaterialModel.bullet_links
    assert b2.last_solve.newton_iterations == 0

"""An arm as the line simulation sees it: the earliest reachable intercept against its closed form."""

import numpy as np
import pytest

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.items import ItemType, Items
from pinarms.optim.line.sim_arm import ArmState, SimArm
from pinarms.optim.line.task_maps import TaskMap
from pinarms.errors import InvalidInput

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)


def const_map(t_a, t_c, du, track=0.5, release=0.1, w=(-0.15, 0.15)):
    du, w = np.asarray(du, float), np.asarray(w, float)
    tc = np.full((du.size, w.size), float(t_c))
    return TaskMap("a", du, w, np.full((du.size, w.size), float(t_a)), tc, track, release, BELT.speed, 0.1)


def test_intercept_is_the_closed_form_of_a_constant_approach():
    # constant approach t_A over the window [u_base - 0.3, u_base + 0.3]: the arm ready at t meets the
    # item at max(t + t_A, t0 + u_min / v) while that is within the window; it leaves at meet - t_A
    m = const_map(0.8, 0.4, np.linspace(-0.3, 0.3, 61))
    items = Items(np.array([0.0, 3.0, 4.0, 30.0]), np.zeros(4), np.zeros(4, int), np.zeros(4), (ItemType("x"),))
    st = ArmState(SimArm("a", 1.0, (m,)), items, BELT.speed)
    assert (st.u_min, st.u_max) == pytest.approx((0.7, 1.3), abs=1e-12)
    t = 8.0
    ok, start, meet, finish, u = st.intercept(t, np.arange(4), items.t0)
    u_min, u_max = 0.7, 1.3
    expect = np.maximum(t + 0.8, items.t0 + u_min / BELT.speed)
    reach = expect <= items.t0 + u_max / BELT.speed + 1e-12
    assert ok.tolist() == reach.tolist() == [False, True, True, True]
    np.testing.assert_allclose(meet[ok], expect[ok], rtol=0, atol=1e-9)
    np.testing.assert_allclose(start[ok], np.maximum(expect[ok] - 0.8, t), rtol=0, atol=1e-9)
    np.testing.assert_allclose(finish[ok], meet[ok] + 0.5 + 0.1 + 0.4, rtol=0, atol=1e-9)
    np.testing.assert_allclose(u[ok], (meet[ok] - items.t0[ok]) * BELT.speed, rtol=0, atol=1e-9)


def test_maps_on_different_grids_are_refused():
    a, b = const_map(0.8, 0.4, [-0.1, 0.0, 0.1]), const_map(0.8, 0.4, [-0.2, 0.0, 0.2])
    items = Items(np.array([0.0]), np.zeros(1), np.zeros(1, int), np.zeros(1), (ItemType("x"), ItemType("y")))
    with pytest.raises(InvalidInput, match="share one du grid"):
        ArmState(SimArm("a", 1.0, (a, b)), items, BELT.speed)

"""pinarms.papers: the published numbers pinned to the printed values (the literals are the point)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pinarms import papers
from pinarms.papers import SEED000, SEED001, SEED002, SEED004


def test_seed000_as_printed():
    assert (SEED000.base_height_mm, SEED000.upper_arm_mm, SEED000.forearm_mm) == (270.0, 250.0, 200.0)
    assert SEED000.path_deg == (55.5, 69.7, 106.5, 124.5)
    assert SEED000.vmax_deg_s == 55.0
    assert (SEED000.ga_population, SEED000.ga_crossover_probability, SEED000.ga_mutation_probability) == (50, 0.7, 0.1)
    assert SEED000.initial_times_s == (2.0, 2.0, 2.0) and SEED000.initial_total_s == 6.0
    assert SEED000.paper_times_s == (1.086, 1.243, 1.278) and SEED000.paper_total_s == 3.607
    assert SEED000.peak_velocity_deg_s == 54.2 and SEED000.reduction_percent == 39.8


def test_seed000_internal_consistency_and_si():
    # Table 3's totals are the sums of its columns; 39.8 % is (6 - 3.607) / 6 = 39.88 %, truncated.
    assert sum(SEED000.paper_times_s) == pytest.approx(SEED000.paper_total_s, abs=1e-12)
    assert sum(SEED000.initial_times_s) == SEED000.initial_total_s
    assert 100 * (1 - SEED000.paper_total_s / SEED000.initial_total_s) == pytest.approx(39.88, abs=0.005)
    np.testing.assert_allclose(SEED000.path_rad, np.radians([55.5, 69.7, 106.5, 124.5]), rtol=1e-15)
    assert SEED000.vmax_rad_s == pytest.approx(0.959931, abs=1e-6)
    np.testing.assert_allclose(SEED000.paper_knot_times_s, [0.0, 1.086, 2.329, 3.607], atol=1e-12)
    np.testing.assert_allclose(SEED000.initial_knot_times_s, [0.0, 2.0, 4.0, 6.0])


def test_seed001_as_printed():
    assert (SEED001.joint_range_deg, SEED001.vmax_deg_s) == (170.0, 210.0)
    assert SEED001.teach_pose_mdh_deg == (0.0, -90.0, 0.0, 90.0, 0.0, 0.0)
    assert SEED001.workspace_samples == 5000
    assert SEED001.sphere_centre_mm == (0.0, 0.0, 160.0) and SEED001.sphere_radius_mm == 600.0
    assert (SEED001.table_z_min_mm, SEED001.table_r_min_mm, SEED001.table_r_max_mm) == (0.0, 200.0, 500.0)
    assert SEED001.via_times_s == (0.0, 1.0, 3.0, 4.0)
    q = SEED001.table2_joints
    assert q.shape == (4, 6)
    np.testing.assert_array_equal(q[0], [-2.6180, -0.8727, 0.9599, 1.4835, -1.5708, 0.0])
    np.testing.assert_array_equal(q[3], [0.7854, 2.2689, 2.3562, 1.4835, -1.5708, -0.7854])
    assert SEED001.table2_cartesian_printed[0] == "(395347244)"
    assert SEED001.table2_p1_p2_mm == ((395.0, 347.0, 244.0), (395.0, 347.0, 289.0))


def test_seed001_table3_rows():
    t, q = SEED001.table3_t_s, SEED001.table3_joints_rad
    assert t.shape == (21,) and q.shape == (21, 3)
    np.testing.assert_allclose(np.diff(t), SEED001.table3_interval_s, atol=1e-12)
    np.testing.assert_array_equal(q[10], [-0.9163, 0.6981, 1.4836])  # t = 2.0 s
    np.testing.assert_array_equal(q[15], [0.7854, 2.2681, 2.1822])  # t = 3.0 s (the 8e-4 rad row)
    # Table 3 starts and ends on Table 2's P1 and P4 (joints 1-3).
    np.testing.assert_array_equal(q[0], SEED001.table2_joints[0, :3])
    np.testing.assert_array_equal(q[-1], SEED001.table2_joints[3, :3])


def test_seed002_as_printed_and_its_table2_row_sums():
    assert SEED002.limits_motor == (100.0, 1500.0, 20_000.0)
    assert (SEED002.bspline_degree, SEED002.segments, SEED002.precision_s) == (5, 10, 0.001)
    h0 = SEED002.initial_durations_s
    np.testing.assert_array_equal(h0, [0.21, 0.15, 0.24, 0.27, 0.19, 0.16, 0.13, 0.23, 0.15, 0.16])
    assert h0.sum() == pytest.approx(SEED002.initial_total_s, abs=1e-12) and SEED002.initial_total_s == 1.89
    assert SEED002.per_joint_totals_s == (1.823, 1.699, 1.726)
    # time saved = 1.89 s - total, for all three joints (section 4)
    np.testing.assert_allclose(1.89 - np.array(SEED002.per_joint_totals_s), SEED002.per_joint_saved_s, atol=1e-12)
    sums = SEED002.table2_durations_s.sum(axis=1)
    assert SEED002.table2_durations_s.shape == (3, 10)
    # Table 2 rows 1 and 2 sum to the printed totals; row 3 sums to 1.759 s, not 1.726 s.
    np.testing.assert_allclose(sums[:2], SEED002.per_joint_totals_s[:2], atol=1e-12)
    assert sums[2] == pytest.approx(1.759, abs=1e-12)
    assert (SEED002.efficiency_gain_percent, SEED002.grasps_per_minute, SEED002.mutation_shape_c) == (10.0, 60.0, 2.0)


def test_seed004_as_printed():
    assert (SEED004.upper_arm_mm, SEED004.forearm_mm, SEED004.waist_to_top_mm, SEED004.wrist_reach_mm) == (
        700.0, 650.0, 900.0, 250.0)
    assert SEED004.lengths_m == pytest.approx((0.7, 0.65, -0.9, 0.25), abs=1e-15)
    assert SEED004.joint_ranges_deg == ((-180.0, 180.0), (0.0, 25.0), (-30.0, 25.0), (-180.0, 180.0))
    angles = SEED004.fk_angles_deg
    assert angles[0] == (-19.8, 5.5, -6.6, 19.8) and angles[2] == (-90.0, 25.0, -30.0, 90.0)
    assert angles[1][:3] == (-49.5, 13.625, -16.35) and math.isnan(angles[1][3])  # θ4 not printed
    assert SEED004.fk_positions_mm == ((455.1, 1513.3, -970.5), (985.7, 1005.1, -918.1), (1197.3, 250.0, -929.2))
    assert SEED004.simulation_positions_mm[1] == (985.7, 1105.0, -918.1)
    assert SEED004.ik_target_mm == SEED004.fk_positions_mm[2]
    assert (SEED004.ik_theta2_deg, SEED004.ik_theta3_down_deg) == (25.0271, 30.0339)
    assert SEED004.ik_theta2_deg in SEED004.ik_theta2_candidates_deg
    assert SEED004.ik_theta3_down_deg in SEED004.ik_theta3_candidates_deg
    np.testing.assert_array_equal(SEED004.ik_answer_deg, [-90.0, 25.0271, -30.0339])
    assert SEED004.simulation_rates_deg_s == (-9.0, 2.5, 3.0, 9.0) and SEED004.simulation_duration_s == 10.0


def test_seed004_si_conversions():
    np.testing.assert_allclose(SEED004.ik_target_m, [1.1973, 0.25, -0.9292], atol=1e-15)
    np.testing.assert_allclose(SEED004.joint_ranges_rad[1], [0.0, np.radians(25.0)])
    np.testing.assert_allclose(SEED004.simulation_rates_rad_s, np.radians([-9.0, 2.5, 3.0, 9.0]))
    assert SEED004.fk_angles_rad.shape == (3, 4) and np.isnan(SEED004.fk_angles_rad[1, 3])
    np.testing.assert_allclose(SEED004.fk_positions_m[0], [0.4551, 1.5133, -0.9705], atol=1e-15)


def test_models_use_the_printed_lengths():
    from pinarms.robots import conventions as conv

    assert (conv.KOJI_A2, conv.KOJI_A3, conv.KOJI_D1, conv.KOJI_H) == pytest.approx(SEED004.lengths_m, abs=1e-15)


@pytest.mark.parametrize("paper", [SEED000, SEED001, SEED002, SEED004])
def test_frozen_and_arrays_are_fresh_copies(paper):
    field = dataclasses.fields(paper)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(paper, field, 0.0)
    a = SEED001.table2_joints
    a[0, 0] = 99.0
    assert SEED001.table2_joints[0, 0] == -2.6180


def test_public_names():
    assert set(papers.__all__) == {"ScaraPaper", "AuboPaper", "GantryPaper", "KojiPaper", "DeltaDatasheet",
                                   "SEED000", "SEED001", "SEED002", "SEED004", "IRB360_1600"}

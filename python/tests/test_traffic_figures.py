"""The traffic figures (throughput through the merge, merging before the lane's end, delay, per
vehicle class) reach Python in the run summary and in the sweep's rows, equal to each other."""

from __future__ import annotations

import mergesim


def test_traffic_figures_in_the_summary_and_the_sweep_rows_agree() -> None:
    result = mergesim.run("mixed_traffic", seed=3)
    traffic = result.summary["traffic"]
    classes = {c["class"]: c for c in traffic["classes"]}
    # Two connected PF-ISO cars and two IDM drivers; the ego is the one merging vehicle.
    assert classes["pf-iso"]["vehicles"] == 2 and classes["idm"]["vehicles"] == 2
    assert traffic["merging"] == 1
    assert sum(c["crossed_section"] for c in classes.values()) == traffic["crossings"]
    crossings = sorted(
        v["crossed_section_at_s"]
        for v in traffic["vehicles"]
        if v["crossed_section_at_s"] is not None
    )
    if len(crossings) >= 2:
        expected = 3600.0 * (len(crossings) - 1) / (crossings[-1] - crossings[0])
        assert abs(traffic["throughput_vph"] - expected) < 1e-6 * expected

    rows = mergesim.sweep("mixed_traffic", runs=1, planners=["pf-iso"], seed=11)
    row = rows.iloc[0]
    again = mergesim.run("mixed_traffic", planner="pf-iso", seed=row["seed"]).summary
    assert row["throughput_vph"] == again["traffic"]["throughput_vph"]
    assert row["merged_before_lane_end"] == again["traffic"]["merged_before_lane_end"]
    assert row["mean_delay_s"] == again["traffic"]["mean_delay_s"]
    assert row["shield_interventions"] == again["shield_interventions"] == 0

#!/usr/bin/env python3
"""Writes the small CommonRoad 2020a test files of this folder (ours, not CommonRoad's; see
README.md). Run from this folder: python3 make_own.py"""
import math


def pts(points):
    return "".join(
        f"<point><x>{x:.4f}</x><y>{y:.4f}</y></point>" for x, y in points
    )


def lanelet(lid, centre, width=3.5, succ=(), pred=(), left=None, right=None, kind="mainCarriageWay"):
    """A lanelet around a centreline given as points, bounds offset along the normals."""
    lb, rb = [], []
    n = len(centre)
    for i, (x, y) in enumerate(centre):
        a = centre[max(i - 1, 0)]
        b = centre[min(i + 1, n - 1)]
        h = math.atan2(b[1] - a[1], b[0] - a[0])
        nx, ny = -math.sin(h), math.cos(h)
        lb.append((x + 0.5 * width * nx, y + 0.5 * width * ny))
        rb.append((x - 0.5 * width * nx, y - 0.5 * width * ny))
    out = [f'  <lanelet id="{lid}">',
           f"    <leftBound>{pts(lb)}</leftBound>",
           f"    <rightBound>{pts(rb)}</rightBound>"]
    out += [f'    <predecessor ref="{p}"/>' for p in pred]
    out += [f'    <successor ref="{s}"/>' for s in succ]
    if left is not None:
        out.append(f'    <adjacentLeft ref="{left}" drivingDir="same"/>')
    if right is not None:
        out.append(f'    <adjacentRight ref="{right}" drivingDir="same"/>')
    out.append(f"    <laneletType>{kind}</laneletType>")
    out.append("  </lanelet>")
    return "\n".join(out)


def state(tag, t, x, y, heading, v):
    return (f"    <{tag}>\n"
            f"      <position><point><x>{x:.4f}</x><y>{y:.4f}</y></point></position>\n"
            f"      <orientation><exact>{heading:.6f}</exact></orientation>\n"
            f"      <time><exact>{t}</exact></time>\n"
            f"      <velocity><exact>{v:.4f}</exact></velocity>\n"
            f"      <acceleration><exact>0.0</exact></acceleration>\n"
            f"    </{tag}>")


def obstacle(oid, y, x0, v, steps, dt):
    """A car driving along +x at y with constant speed v, for `steps` time steps."""
    traj = "\n".join(state("state", k, x0 + v * k * dt, y, 0.0, v).replace("    <", "      <").replace("      </state>", "      </state>")
                     for k in range(1, steps + 1))
    return (f'  <dynamicObstacle id="{oid}">\n    <type>car</type>\n'
            f"    <shape><rectangle><length>4.5</length><width>1.8</width></rectangle></shape>\n"
            f"{state('initialState', 0, x0, y, 0.0, v)}\n"
            f"    <trajectory>\n{traj}\n    </trajectory>\n  </dynamicObstacle>")


def planning_problem(pid, x, y, heading, v, goal):
    return (f'  <planningProblem id="{pid}">\n'
            f"{state('initialState', 0, x, y, heading, v)}\n"
            f"    <goalState>\n{goal}\n    </goalState>\n  </planningProblem>")


def doc(bid, body):
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            "<!-- Written by make_own.py for mergesim's tests (not a CommonRoad benchmark). -->\n"
            f'<commonRoad commonRoadVersion="2020a" timeStepSize="0.1" benchmarkID="{bid}" '
            'author="mergesim" affiliation="mergesim tests" source="hand-made" date="2026-12-02">\n'
            f"{body}\n</commonRoad>\n")


dt = 0.1
# An acceleration lane (lanelet 2, y = -3.5, 200 m at full width, then a 60 m taper: its right
# bound rises to its left one) that ends beside a main lane (lanelet 1, 700 m, y = 0), as the
# lower lane of the paper's urgent merge road.


def accel_lanelet():
    left = [(0.0, -1.75), (200.0, -1.75), (260.0, -1.75)]
    right = [(0.0, -5.25), (200.0, -5.25), (260.0, -1.75)]
    return "\n".join([
        '  <lanelet id="2">',
        f"    <leftBound>{pts(left)}</leftBound>",
        f"    <rightBound>{pts(right)}</rightBound>",
        '    <adjacentLeft ref="1" drivingDir="same"/>',
        "    <laneletType>accessRamp</laneletType>",
        "  </lanelet>",
    ])


main = [(x, 0.0) for x in (0.0, 200.0, 260.0, 700.0)]
goal = ("      <position><rectangle><length>20.0</length><width>3.5</width>"
        "<orientation>0.0</orientation><center><x>400.0</x><y>0.0</y></center></rectangle></position>\n"
        "      <time><intervalStart>0</intervalStart><intervalEnd>250</intervalEnd></time>")
body = "\n".join([
    lanelet(1, main, right=2),
    accel_lanelet(),
    obstacle(100, 0.0, 35.0, 15.0, 200, dt),
    planning_problem(200, 10.0, -3.5, 0.0, 20.0, goal),
])
open("acceleration_lane.xml", "w").write(doc("OWN_AccelerationLane-1", body))

# A Y-merge: a main lanelet 10 along y = 0 and a ramp lanelet 11 curving in from y = -15 m
# (y = -15 (1 - x/100)², heading 0 where it ends) share one successor, lanelet 12.
ramp = [(x, -15.0 * (1.0 - x / 100.0) ** 2) for x in range(0, 101, 5)]
body = "\n".join([
    lanelet(10, [(0.0, 0.0), (100.0, 0.0)], succ=(12,)),
    lanelet(11, ramp, succ=(12,), kind="accessRamp"),
    lanelet(12, [(100.0, 0.0), (300.0, 0.0)], pred=(10, 11)),
    obstacle(101, 0.0, 20.0, 14.0, 100, dt),
    planning_problem(201, 5.0, ramp[1][1], math.atan2(ramp[2][1] - ramp[0][1], 10.0), 15.0,
                     '      <position><lanelet ref="12"/></position>\n'
                     "      <velocity><intervalStart>10.0</intervalStart><intervalEnd>20.0</intervalEnd></velocity>"),
])
open("y_merge.xml", "w").write(doc("OWN_YMerge-1", body))

# A fork: a main lanelet 20 (100 m along y = 0) with two successors: lanelet 21 straight on
# (200 m) and an exit lanelet 22 leaving to the right (y = −20 (x'/150)², x' from the fork,
# 150 m along x). No obstacle, no planning problem: scenario TOMLs place their own cars.
exit_ramp = [(100.0 + x, -20.0 * (x / 150.0) ** 2) for x in range(0, 151, 5)]
body = "\n".join([
    lanelet(20, [(0.0, 0.0), (100.0, 0.0)], succ=(21, 22)),
    lanelet(21, [(100.0, 0.0), (300.0, 0.0)], pred=(20,)),
    lanelet(22, exit_ramp, pred=(20,), kind="exitRamp"),
])
open("fork.xml", "w").write(doc("OWN_Fork-1", body))

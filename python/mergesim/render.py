"""Top-down RGB pictures of the merge road and its vehicles (numpy only)."""

from __future__ import annotations

from typing import Mapping, Sequence, Tuple

import numpy as np

_GRASS = (88, 130, 72)
_ASPHALT = (70, 70, 74)
_LINE = (235, 235, 235)
_AGENT = (220, 40, 40)
_OTHER = (50, 110, 220)
_DASH_M = 3.0
_LINE_HALF_WIDTH_M = 0.12


def lower_edge_y_m(road: Mapping[str, float], x_m: np.ndarray) -> np.ndarray:
    """The lower road edge at ``x_m``: straight, tapering up by one lane over the merge section."""
    start, end = road["merge_start_x_m"], road["merge_end_x_m"]
    w = np.clip((x_m - start) / (end - start), 0.0, 1.0)
    return road["y_bottom_m"] + w * road["lane_width_m"]


def top_down(
    road: Mapping[str, float],
    states: np.ndarray,
    sizes_m: Sequence[Tuple[float, float]],
    agent: int,
    width_px: int = 640,
    height_px: int = 128,
    m_per_px: float = 0.15,
) -> np.ndarray:
    """An RGB picture (``height_px × width_px × 3``, uint8) of the road around vehicle ``agent``.

    Args:
        road: The road (``MergeEnv.road``).
        states: One row per vehicle, x_m and y_m (CoG) and yaw_rad first.
        sizes_m: (length, width) of every vehicle (m).
        agent: The vehicle in view (drawn red, a quarter of the picture from the left edge).
        width_px, height_px, m_per_px: Picture size and scale.
    """
    x0 = states[agent, 0] - 0.25 * width_px * m_per_px
    y_mid = road["y_bottom_m"] + road["lane_width_m"]
    y_top = y_mid + 0.5 * height_px * m_per_px
    xs = x0 + (np.arange(width_px) + 0.5) * m_per_px
    ys = y_top - (np.arange(height_px) + 0.5) * m_per_px
    X, Y = np.meshgrid(xs, ys)
    image = np.empty((height_px, width_px, 3), dtype=np.uint8)
    image[:] = _GRASS
    lower = lower_edge_y_m(road, xs)[None, :]
    upper = road["y_bottom_m"] + 2.0 * road["lane_width_m"]
    on_road = (Y >= lower) & (Y <= upper) & (X >= road["start_x_m"]) & (X <= road["end_x_m"])
    image[on_road] = _ASPHALT
    half_line_m = max(_LINE_HALF_WIDTH_M, 0.6 * m_per_px)
    edges = (np.abs(Y - upper) < half_line_m) | (np.abs(Y - lower) < half_line_m)
    divider = (
        (np.abs(Y - y_mid) < half_line_m)
        & (X < road["merge_end_x_m"])
        & (np.mod(X, 2.0 * _DASH_M) < _DASH_M)
    )
    image[(edges | divider) & (X >= road["start_x_m"]) & (X <= road["end_x_m"])] = _LINE
    x1 = x0 + width_px * m_per_px
    order = [i for i in range(len(states)) if i != agent] + [agent]
    for i in order:
        x, y, yaw = states[i, 0], states[i, 1], states[i, 2]
        length, width = sizes_m[i]
        if x + length < x0 or x - length > x1:
            continue
        c, s = np.cos(yaw), np.sin(yaw)
        dx, dy = X - x, Y - y
        along = dx * c + dy * s
        across = -dx * s + dy * c
        body = (np.abs(along) <= 0.5 * length) & (np.abs(across) <= 0.5 * width)
        image[body] = _AGENT if i == agent else _OTHER
    return image

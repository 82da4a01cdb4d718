"""``mergesim.register_planner``: planners written in Python, by name, wherever a planner name goes.

A planner is an object with ``plan(observation) -> decision``; what is registered is a callable
that makes one (usually its class). Every vehicle driven by the name gets its own object, made
when the run starts; the simulator calls its ``plan`` at each of the vehicle's planning cycles
(10 Hz in the built-in scenarios). python/README.md ("Planners in Python") lists the
observation's keys, the decision's form and what a cycle costs.
"""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Mapping, Protocol, Sequence, Tuple, Union

from . import _native
from ._native import ScenarioError

#: A path point: a dict with ``x_m``, ``y_m``, ``speed_mps``, ``t_s`` (absolute time, s), or
#: the tuple ``(x_m, y_m, speed_mps, t_s)``.
PathPoint = Union[Mapping[str, float], Tuple[float, float, float, float], Sequence[float]]
#: What ``plan`` returns: the path alone, or ``{"path": [...], "broadcast": True,
#: "fallback": None}``.
Decision = Union[Sequence[PathPoint], Mapping[str, Any]]


class Planner(Protocol):
    """What a Python planner looks like (any object with this method will do)."""

    def plan(self, observation: Dict[str, Any]) -> Decision:
        """One planning cycle: the observation in, the path to follow out."""
        ...


def register_planner(name: str, factory: Callable[[], Planner]) -> None:
    """Registers a planner written in Python under ``name``, next to the built-in ones: from then
    on ``name`` runs in :func:`mergesim.run` (``planner=name``), a scenario's
    ``driver = { planner = "name" }``, :func:`mergesim.sweep` (``planners=[..., name]``),
    :func:`mergesim.study` plans, and :class:`mergesim.MergeEnv` (``planner=name``: the other
    vehicles' planner). It is listed by :func:`mergesim.planners`.

    Args:
        name: The planner's name: non-empty, without spaces, commas or quotes, and not taken
            (a built-in planner, ``external``, or a planner registered already).
        factory: Called without arguments once per vehicle when a run starts; returns the
            vehicle's planner, an object with ``plan(observation) -> decision``. A class is
            the usual factory.

    Raises:
        ScenarioError: A bad or taken name, or a factory that is not callable.

    A planner's exception (or a bad decision: empty path, a value not finite, a negative
    speed, times not increasing) ends its run with :class:`mergesim.SimulationError` in
    :func:`mergesim.run`, a row with status ``diverged`` (the sweep's status of any run that
    failed) in :func:`mergesim.sweep`, its ``error`` saying ``behaviour of vehicle V: Python
    planner 'name': ValueError: ... (File ..., line ..., in plan)``, and an episode end with ``info["error"]``
    in :class:`mergesim.MergeEnv`.
    """
    if not isinstance(name, str):
        raise ScenarioError(f"planner name: must be a string, got {type(name).__name__}")
    if isinstance(factory, type) and not callable(getattr(factory, "plan", None)):
        raise ScenarioError(
            f"planner {name!r}: class {factory.__name__} has no plan(observation) method"
        )
    _native.register_planner(name, factory)


def unregister_planner(name: str) -> None:
    """Removes the Python planner ``name`` (built-in planners cannot be removed).

    Raises:
        ScenarioError: ``name`` is not a registered Python planner.
    """
    _native.unregister_planner(name)


def python_planners() -> List[str]:
    """The names of the registered Python planners, sorted."""
    return list(_native.python_planners())

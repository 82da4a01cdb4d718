"""Argument conversion shared by run, sweep and the environment."""

from __future__ import annotations

import json
import operator
import os
from typing import Any, Mapping, Optional, Union

from ._native import ScenarioError

#: A scenario: a built-in name, a path to a TOML file, or TOML text (any string with a line break).
ScenarioSource = Union[str, "os.PathLike[str]"]

_U64_MAX = 2**64 - 1


def scenario_arg(scenario: ScenarioSource) -> str:
    """The scenario argument as the native module takes it (a string)."""
    if isinstance(scenario, (str, os.PathLike)):
        return os.fspath(scenario)
    raise ScenarioError(
        f"scenario: expected a built-in name, a path or TOML text, got {type(scenario).__name__}"
    )


def params_json(params: Optional[Mapping[str, Any]]) -> Optional[str]:
    """The overrides as JSON (None: no overrides)."""
    if params is None:
        return None
    if not isinstance(params, Mapping):
        raise ScenarioError(
            "params: must be a dict of the scenario's tables and keys, "
            f"e.g. {{'sim': {{'mu': 0.5}}}}, got {type(params).__name__}"
        )
    try:
        return json.dumps(params, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ScenarioError(f"params: {e}") from None


def _integer(value: object) -> Optional[int]:
    """`value` as a Python int if it is an integer (int, numpy.uint64, ...; not a bool)."""
    if isinstance(value, bool):
        return None
    try:
        return operator.index(value)  # type: ignore[call-overload]
    except TypeError:
        return None


def seed_arg(name: str, seed: object) -> int:
    """A seed: an integer in 0..2**64-1 (numpy integers too, e.g. a sweep row's ``seed``), or a
    string as the result files write it (``"0x88be3e3d6d9f1a2d"``, or decimal digits). A float
    is refused: a seed that went through a double (``9.853264649648847e18``) has lost digits and
    would silently run another instance."""
    if isinstance(seed, str):
        from ._native import parse_seed

        try:
            return parse_seed(seed)
        except ScenarioError as e:
            raise ScenarioError(f"{name}: {e}") from None
    value = _integer(seed)
    if value is None or not 0 <= value <= _U64_MAX:
        hint = ""
        if isinstance(seed, float) or type(seed).__name__.startswith("float"):
            hint = (
                " (a float cannot be an exact seed: a seed read as a float has lost digits; "
                "take it from the file as written, \"0x...\", or replay with sweep_seed and "
                "instance)"
            )
        raise ScenarioError(f"{name} = {seed!r}: need an integer from 0 to {_U64_MAX}{hint}")
    return value


def optional_seed_arg(name: str, seed: object) -> Optional[int]:
    """None or a seed (:func:`seed_arg`)."""
    return None if seed is None else seed_arg(name, seed)


def count_arg(name: str, value: object) -> int:
    """A positive integer (numpy integers too)."""
    number = _integer(value)
    if number is None or number < 1:
        raise ScenarioError(f"{name} = {value!r}: need a positive integer")
    return number


def optional_count_arg(name: str, value: object) -> Optional[int]:
    """None or a positive integer (:func:`count_arg`)."""
    return None if value is None else count_arg(name, value)

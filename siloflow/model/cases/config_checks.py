"""What every configuration check shares: the error that names the key, and the checks that a name refers to
something defined.

The checks of the configuration as a whole live in :mod:`siloflow.engines.config`; each case kind's own checks live with its
case model and are named by its registry entry (:attr:`siloflow.model.cases.kinds.CaseKind.check_config`).
"""

from __future__ import annotations

from typing import Iterable, Mapping

__all__ = ["ConfigError", "require", "require_subset"]


class ConfigError(ValueError):
    """A configuration value is invalid; the message names the key."""


def require(name: str, defined: Mapping, key: str, what: str) -> None:
    """``name`` (the value of config key ``key``) must be one of ``defined``'s keys, a ``what`` (e.g. ``material``).

    Raises
    ------
    ConfigError
        Naming the key, the name and what is defined.
    """
    if name not in defined:
        known = ", ".join(sorted(defined)) or "none"
        raise ConfigError(f"config key '{key}': unknown {what} '{name}'; defined: {known}")


def require_subset(chosen: Iterable | None, among, key: str, among_key: str) -> None:
    """A list key that picks from another list (null picks all): every entry must be in ``among``.

    Raises
    ------
    ConfigError
        Naming the entry of ``key`` that is not among ``among_key``.
    """
    for index, name in enumerate(chosen or []):
        if name not in among:
            raise ConfigError(f"config key '{key}[{index}]': '{name}' is not among {among_key} {list(among)}")

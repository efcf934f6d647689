"""Fixtures of the classroom tests that need a served app (a hub behind real tabs): :mod:`tests.support.fixtures`."""

from tests.support.fixtures import app, connect, whole_steps

__all__ = ["app", "connect", "whole_steps"]

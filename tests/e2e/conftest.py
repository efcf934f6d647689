"""Fixtures of the end-to-end tests: a served app, protocol clients, headless Chromium
(:mod:`tests.support.fixtures`)."""

from tests.support.fixtures import app, browser, connect, whole_steps

__all__ = ["app", "browser", "connect", "whole_steps"]

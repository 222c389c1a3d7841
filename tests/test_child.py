"""The child process that runs functions for rvfem (rvfem._child): results, errors, an ending child."""

from __future__ import annotations

import math
import os

import pytest

from rvfem._child import ChildProcess


def test_calls_run_in_order_in_another_process_and_their_errors_come_back():
    with ChildProcess("test") as child:
        pid = child.call(os.getpid)
        square = child.call(math.pow, 3.0, 2.0)
        failing = child.call(math.sqrt, -1.0)
        assert pid.result(timeout=30) != os.getpid()
        assert square.result(timeout=30) == 9.0
        with pytest.raises(ValueError, match="math domain"):
            failing.result(timeout=30)
        assert child.call(math.floor, 2.5).result(timeout=30) == 2    # the child goes on after an error


def test_a_child_that_ends_fails_its_pending_calls():
    with ChildProcess("test") as child:
        with pytest.raises(RuntimeError, match="the test process ended.*exit code 3"):
            child.call(os._exit, 3).result(timeout=30)

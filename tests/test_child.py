"""The child process that runs functions for rvfem (rvfem._child): results, errors, an ending child."""

from __future__ import annotations

import math
import os
import pickle

import pytest

from rvfem._child import ChildProcess, ChildProcessEnded


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


def test_a_child_that_ends_fails_its_pending_calls_and_the_later_ones():
    with ChildProcess("test") as child:
        ending = child.call(os._exit, 3)
        after = child.call(math.floor, 2.5)              # sent before the child ended
        with pytest.raises(ChildProcessEnded, match="the test process ended.*exit code 3"):
            ending.result(timeout=30)
        with pytest.raises(ChildProcessEnded):
            after.result(timeout=30)
        with pytest.raises(ChildProcessEnded):           # made after it ended: fails at once
            child.call(math.floor, 2.5).result(timeout=1)


def test_a_call_that_cannot_be_sent_raises_at_once():
    with ChildProcess("test") as child:
        with pytest.raises((pickle.PicklingError, AttributeError)):
            child.call(lambda: 1)                        # a lambda does not pickle
        assert child.call(math.floor, 2.5).result(timeout=30) == 2

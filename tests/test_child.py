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


def test_a_background_call_runs_beside_the_calls_of_the_main_thread():
    import time

    with ChildProcess("test") as child:
        sleeping = child.call(time.sleep, 3.0, background=True)
        pid = child.call(os.getpid)                  # sent after it, answered while it sleeps
        pid.result(timeout=30)
        assert not sleeping.done()
        assert sleeping.result(timeout=30) is None


def test_the_environment_and_the_end_of_a_child_reach_the_parent():
    with ChildProcess("test", env={**os.environ, "RVFEM_CHILD_PROBE": "42"}) as child:
        assert child.call(os.getenv, "RVFEM_CHILD_PROBE").result(timeout=30) == "42"
        ending = child.call(os.abort)
        with pytest.raises(ChildProcessEnded) as info:
            ending.result(timeout=30)
    assert info.value.returncode < 0            # killed by SIGABRT
    assert pickle.loads(pickle.dumps(info.value)).returncode == info.value.returncode


def test_forwarded_log_records_are_logged_again_here(caplog):
    import logging

    with caplog.at_level(logging.INFO, logger="rvfem.test_child"):
        with ChildProcess("test", forward_logs=True) as child:
            child.call(logging.getLogger("rvfem.test_child").info, "from the child").result(timeout=30)
            child.call(math.floor, 1.5).result(timeout=30)      # the record came before this answer
    assert [(r.name, r.getMessage()) for r in caplog.records] == [("rvfem.test_child", "from the child")]

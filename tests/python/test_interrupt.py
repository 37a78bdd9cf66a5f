"""Ctrl-C during long calls: the test sends SIGINT to its own process from a timer thread while
train / evaluate / leaderboard run in C++ without the GIL; the call ends with KeyboardInterrupt
within a second or so, and leaves no output file (nor a temporary one) behind."""
import os
import signal
import threading
import time

import pytest

import dicestack
from conftest import short_world


@pytest.fixture(scope="module")
def few(builtin_episodes):
    return builtin_episodes[:10]


@pytest.fixture(scope="module")
def knn(few):
    return dicestack.train("knn", demos=few, params={"k": 2}, progress=False)


def interrupted(call, after=0.5):
    """Runs call() with a SIGINT sent to this process `after` seconds in; returns the seconds the
    call took to stop. Fails if it finished without being interrupted."""
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    timer = threading.Timer(after, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
        timer.join()
    return time.monotonic() - start


def test_ctrl_c_stops_a_long_train(few, tmp_path):
    out = tmp_path / "dagger.dsm"
    seconds = interrupted(lambda: dicestack.train(
        "knn", learner="dagger", demos=few, out=out, threads=2, progress=True,
        options={"iterations": 1000, "rollouts": 50, "expert": "scripted"}))
    assert seconds < 5
    assert list(tmp_path.iterdir()) == []  # neither the model nor a temporary file
    # The interpreter and the library carry on.
    assert dicestack.train("knn", demos=few, params={"k": 2}, progress=False).regressor == "knn"


def test_ctrl_c_stops_a_python_regressor_in_its_own_code(few):
    class Slow:
        def fit(self, x, y):
            while True:
                time.sleep(0.01)

        def predict(self, x):
            raise AssertionError("never fitted")

    dicestack.register_regressor("test_slow_fit", Slow)
    assert interrupted(lambda: dicestack.train("test_slow_fit", demos=few, progress=False)) < 5


def test_ctrl_c_stops_an_evaluation(knn):
    assert interrupted(lambda: dicestack.evaluate(knn, episodes=30000, threads=2, progress=False)) < 5


def test_ctrl_c_stops_a_leaderboard_and_keeps_no_table(few, tmp_path):
    demos = tmp_path / "demos"
    dicestack.save_demos(few, demos)
    out = tmp_path / "board.md"
    seconds = interrupted(lambda: dicestack.leaderboard(
        ["knn"], ["dagger"], demos, options={"iterations": 1000, "expert": "scripted"}, episodes=2,
        world=short_world(200), out=out, progress=False))
    assert seconds < 5
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demos"]

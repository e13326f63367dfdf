"""Watching and stopping a long call: the progress callable, a CancelToken cancelled from
another thread, and Ctrl-C (SIGINT) while the computation runs without the GIL."""

import _thread
import os
import signal
import threading

import numpy as np
import pytest

import toposmooth


def noisy(n=300, seed=3):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n] / n
    return np.sin(6 * x) * np.cos(5 * y) + 0.3 * rng.random((n, n))


def test_progress_tells_the_stages_in_order_with_fractions_on_the_caller_s_thread():
    events = []
    me = threading.get_ident()

    def progress(stage, fraction, message):
        assert threading.get_ident() == me, "called on the calling thread"
        events.append((stage, fraction, message))

    r = toposmooth.smooth(noisy(60), persistence="2%", progress=progress)
    assert r.certified
    stages = [e[0] for e in events]
    for stage in ["selection", "representative", "solve", "certificate"]:
        assert stage in stages, stages
    # the Morse-Smale complex is built for the separatrix representative
    assert "complex" not in stages
    toposmooth.smooth(noisy(60), persistence="2%", representative="separatrix", progress=progress)
    assert "complex" in [e[0] for e in events]
    solve = [f for s, f, _ in events if s == "solve" and f is not None]
    assert solve and all(0.0 <= f <= 1.0 for f in solve) and solve[-1] == 1.0, solve
    assert any("iteration" in m for s, _, m in events if s == "solve"), "the solver's own words"


def test_a_token_cancelled_from_another_thread_stops_the_run():
    token = toposmooth.CancelToken()
    started = threading.Event()

    def progress(stage, fraction, message):
        if stage == "solve":
            started.set()

    threading.Thread(target=lambda: started.wait(60) and token.cancel(), daemon=True).start()
    with pytest.raises(toposmooth.Cancelled) as e:
        toposmooth.smooth(noisy(), persistence="1%", progress=progress, cancel=token)
    assert e.value.exit_code == 130 and e.value.kind == "cancelled"
    assert token.cancelled and started.is_set()
    # a cancelled token stops the next call at once; a fresh one does not
    with pytest.raises(toposmooth.Cancelled):
        toposmooth.smooth(noisy(40), cancel=token)
    assert toposmooth.smooth(noisy(40), cancel=toposmooth.CancelToken()).certified


def test_ctrl_c_raises_keyboard_interrupt_once_the_run_has_stopped():
    # SIGINT as the terminal sends it, to this (main) thread, while the solver iterates; with
    # Python's own handler even where the tests run in a background shell, which starts
    # Python with SIGINT ignored (interrupt_main then does nothing)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        ctrl_c_while_the_solver_iterates()
    finally:
        signal.signal(signal.SIGINT, previous)


def ctrl_c_while_the_solver_iterates():
    sent = []

    def progress(stage, fraction, message):
        if stage == "solve" and not sent:
            sent.append(stage)
            _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        toposmooth.smooth(noisy(), persistence="1%", progress=progress)
    assert sent == ["solve"]
    # the package works on afterwards
    assert toposmooth.smooth(noisy(30)).certified


def test_an_exception_in_the_progress_callable_stops_the_run_and_is_raised():
    def progress(stage, fraction, message):
        if stage == "representative":
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        toposmooth.smooth(noisy(80), progress=progress)


def test_a_cancelled_command_in_process_leaves_no_temporary_and_no_output(tmp_path):
    h = noisy()
    src = tmp_path / "noise.npy"
    np.save(src, h)
    token = toposmooth.CancelToken()

    def progress(stage, fraction, message):
        if stage == "solve":
            token.cancel()

    with pytest.raises(toposmooth.Cancelled):
        toposmooth.cli(
            "smooth", src, "-o", tmp_path / "out.vti", "--persistence", "1%", "--report", tmp_path / "r.json",
            progress=progress, cancel=token,
        )
    assert sorted(os.listdir(tmp_path)) == ["noise.npy"]

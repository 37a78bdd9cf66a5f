"""The progress bar's estimate of the time left counts from the first fraction above 0: work shown
at 0 % before it (the tracker preparing its paths) has no known share of the job."""
import io

from dicestack import _progress


def test_the_time_left_counts_from_the_first_fraction_above_zero(monkeypatch):
    now = [0.0]
    monkeypatch.setattr(_progress.time, "monotonic", lambda: now[0])
    stream = io.StringIO()
    bar = _progress.ProgressBar(stream)
    for t, fraction in [(0.0, 0.0), (100.0, 0.0), (200.0, 0.1), (300.0, 0.55)]:
        now[0] = t
        bar.update(fraction, "work")
    lines = stream.getvalue().splitlines()
    assert len(lines) == 4
    assert all("left" not in line for line in lines[:3])
    # 0.45 of the job in the 100 s since 0.1: 0.45 left takes 100 s more (from the start: 245 s).
    assert lines[3].endswith("elapsed 5:00, left ~1:40")

"""The progress bar of long calls (train, evaluate, leaderboard), drawn on stderr as the command
line draws its own: `[#####---------------]  25% text  elapsed 0:03, left ~0:09`. On a terminal
it redraws one line (at most ten times a second); elsewhere it prints a line at most every 10 s.
The C++ side calls update() from the calling thread with the GIL briefly taken."""
import sys
import time


def _clock(seconds):
    s = int(seconds + 0.5)
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


class ProgressBar:
    def __init__(self, stream=None):
        self._stream = stream if stream is not None else sys.stderr
        try:
            self._tty = self._stream.isatty()
        except (AttributeError, ValueError):
            self._tty = False
        self._start = time.monotonic()
        self._last = None
        self._drawn = False
        # The time left counts from the first fraction above 0: work shown at 0 % before it (the
        # tracker preparing its paths) has no known share of the job.
        self._counted = None  # (time, fraction)

    def update(self, fraction, text):
        now = time.monotonic()
        if self._counted is None and fraction > 0.0:
            self._counted = (now, min(float(fraction), 1.0))
        quiet = 0.1 if self._tty else 10.0
        if self._last is not None and now - self._last < quiet and fraction < 1.0:
            return
        self._last = now
        fraction = min(max(float(fraction), 0.0), 1.0)
        elapsed = now - self._start
        filled = int(fraction * 20)
        line = f"[{'#' * filled}{'-' * (20 - filled)}] {100 * fraction:3.0f}% {text}  elapsed {_clock(elapsed)}"
        if self._counted is not None and fraction - self._counted[1] > 0.01:
            counted = fraction - self._counted[1]
            line += f", left ~{_clock((now - self._counted[0]) * (1 - fraction) / counted)}"
        self._stream.write(f"\r\033[K{line}" if self._tty else line + "\n")
        self._stream.flush()
        self._drawn = True

    def close(self):
        if self._tty and self._drawn:
            self._stream.write("\n")
            self._stream.flush()


def progress_bar(progress):
    """The bar a long call draws: progress True or False, or None for "when stderr is a terminal"."""
    if progress is None:
        try:
            progress = sys.stderr.isatty()
        except (AttributeError, ValueError):
            progress = False
    if not isinstance(progress, bool):
        raise TypeError(f"progress must be True, False or None, got {type(progress).__name__}")
    return ProgressBar() if progress else None

"""Progress lines for long work: count, rate and ETA on stderr, at most every ``interval`` s."""

from __future__ import annotations

import sys
import time


class Progress:
    """Report ``done/total`` with rate and ETA; ``update`` is cheap to call often.

    >>> progress = Progress("value iteration", total=100, unit="sweeps")
    >>> progress.update(10)  # prints at most every `interval` seconds
    >>> progress.finish()
    """

    def __init__(
        self,
        label: str,
        total: int,
        unit: str = "items",
        interval: float = 1.0,
        at_most: bool = False,
    ):
        """``at_most``: ``total`` is a cap the work may stop well short of (value iteration's
        sweeps until it converges): the line says so and its ETA is an upper bound (a DP that
        took 16 s printed ETA 2883 s, its cap of 3,000 sweeps at the rate so far)."""
        self.label = label
        self.total = max(int(total), 1)
        self.unit = unit
        self.at_most = at_most
        self.interval = interval
        self.start = time.perf_counter()
        self.last = self.start
        self.done = 0

    def update(self, done: int, note: str = "") -> None:
        """``done`` of ``total`` so far: a line if ``interval`` has passed since the last, and
        the work is not yet all done (its end is ``finish``'s to say: a first population of one
        round, slow to compile, printed '1/1 rounds (0.0 rounds/s, ETA 0.0 s)')."""
        self.done = done
        now = time.perf_counter()
        if now - self.last >= self.interval and done < self.total:
            self.last = now
            self._print(now, note)

    def _print(self, now: float, note: str) -> None:
        elapsed = max(now - self.start, 1e-9)
        rate = self.done / elapsed
        eta = (self.total - self.done) / rate if rate > 0 else float("inf")
        extra = _after(note)
        cap, bound = (f", {self.total} at most", "at most ") if self.at_most else ("", "")
        print(
            f"{self.label}: {self.done}/{self.total} {self.unit}{cap} "
            f"({rate:.1f} {self.unit}/s, ETA {bound}{eta:.1f} s){extra}",
            file=sys.stderr,
            flush=True,
        )

    def finish(self, note: str = "") -> None:
        now = time.perf_counter()
        elapsed = now - self.start
        extra = _after(note)
        print(
            f"{self.label}: done, {self.done} {self.unit} in {elapsed:.2f} s{extra}",
            file=sys.stderr,
            flush=True,
        )


def _after(note: str) -> str:
    """A progress line's note as it follows the counts: after a comma ('..., best fitness
    0.812'), or a space where it is a remark in brackets; nothing for none."""
    if not note:
        return ""
    return f" {note}" if note.startswith("(") else f", {note}"

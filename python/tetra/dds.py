"""tetra over DDS from Python (docs/python.md, "DDS"): a simulator's end of the wire to ``tetra fusion``.

Built on tetra's own DDS layer (C++ over Cyclone DDS's libddsc, the layer ``tetra play``, ``tetra command``
and the service use): no Python DDS binding is needed. Values are in SI units with the names of
idl/tetra.idl: ``q_RB_wxyz`` (body -> reference, Hamilton, scalar first), ``omega_BR_B_rad_s``,
``sigma_rad`` and ``protection_level_rad`` per body axis, sensor times as ``stamp_ns`` [ns] and ``time_s``.

- ``GyroPublisher``: gyro epochs out (raw outputs [V], one per gyro), with the epoch's reference if any.
- ``Lockstep``: the same, and each ``step`` waits for the service's Attitude of that epoch: the service's
  pace is the simulator's, and its numbers are ``tetra.Pipeline``'s on the same epochs, bit for bit.
- ``ReferencePublisher``: a star tracker of its own, stamping each reference with its image's time.
- ``Subscriber``: the unit's Attitude (every epoch), Health and FdiEvent as dataclasses.
- ``command``: an operator command (reset, exclude, reinstate) and its acknowledgement.

Every wait takes ``timeout_s`` and raises ``TimeoutError`` when it passes (naming what did not come);
Ctrl-C raises ``KeyboardInterrupt`` within about 10 ms of any wait; the library's errors raise
``tetra.BadInputError`` / ``tetra.Error``. ``domain=None`` is the configuration's default domain
(``CYCLONEDDS_URI``, as for ``tetra``).
"""
from __future__ import annotations

import dataclasses
import getpass
import socket
from collections import deque
from typing import Any, Callable, Deque, Dict, List, Optional, TypeVar

from . import _tetra

__all__ = ["Attitude", "FdiEvent", "GyroPublisher", "GyroStatus", "Health", "Lockstep", "ReferencePublisher",
           "Subscriber", "command"]

if not getattr(_tetra, "_HAS_DDS", False):  # pragma: no cover - a build without TETRA_WITH_DDS
    raise ImportError("tetra.dds: this tetra was built without DDS (TETRA_WITH_DDS=OFF)")


@dataclasses.dataclass(frozen=True)
class Attitude:
    """One fused attitude (the ``Attitude`` topic), one per accepted epoch."""
    stamp_ns: int                 #: [ns] sensor time of the epoch
    time_s: float                 #: [s] the same
    q_RB_wxyz: Any                #: (4,) body -> reference, scalar first
    omega_BR_B_rad_s: Any         #: (3,) [rad/s] rate of B relative to R, in B
    sigma_rad: Any                #: (3,) [rad] 1-sigma per body axis
    protection_level_rad: Any     #: (3,) [rad] integrity bound per body axis (inf: none)
    mode: str                     #: NOMINAL, DEGRADED, SUSPECT, LOST
    gyros: List[int]              #: the gyros used (ids 1..N)
    gyros_mask: int               #: the same as a mask (bit i-1: gyro i)
    fdi_available: bool           #: False: a new fault would go unseen


@dataclasses.dataclass(frozen=True)
class GyroStatus:
    state: str                    #: OK, ABSENT, INVALID, SUSPECT, EXCLUDED
    kind: str                     #: the fault kind isolated (none)
    bias_rad_s: float             #: [rad/s] the filter's estimate of the gyro's bias
    bias_sigma_rad_s: float       #: [rad/s] its 1-sigma


@dataclasses.dataclass(frozen=True)
class Health:
    """The service's health of the unit (the ``Health`` topic): at least every ``health_period_s``."""
    unit: str
    stamp_ns: int
    time_s: float
    mode: str
    used: List[int]
    gyros: List[GyroStatus]
    parity_residual: float
    chi2: float
    cusum: float
    chi2_threshold: float
    cusum_threshold: float
    fdi_available: bool
    reference_state: str          #: absent, accepted, rejected
    reference_nis: float
    protection_level_rad: Any     #: (3,) [rad]
    references_delayed: int       #: references fused at their own (earlier) stamp
    references_too_late: int      #: references beyond the fusion horizon: left out
    reference_horizon_s: float    #: [s]
    counters: Dict[str, int]      #: the SampleCounters of idl/tetra.idl
    events_published: int
    gyro_writers: int
    health_period_s: float        #: [s]


@dataclasses.dataclass(frozen=True)
class FdiEvent:
    """An FDI event or a command's acknowledgement (the ``FdiEvent`` topic). The keys of ``tetra.Pipeline``'s
    event dicts (``json`` is the line ``tetra replay --events`` writes), and the wire's own."""
    unit: str
    event_seq: int
    stamp_ns: int
    time_s: float
    type: str
    gyro: Optional[int]
    test: str
    statistic: float
    kind: str
    evidence: str
    gyros: List[int]
    command: Optional[str]
    outcome: str
    why: str
    detail: str
    json: str
    command_id: int = 0           #: the acknowledged command's id (0: not an acknowledgement)
    force: bool = False           #: acknowledgements only: the command said force
    refused: bool = False         #: acknowledgements only: refused (``detail`` says why), nothing changed
    operator: str = ""
    origin: str = ""


_Publisher = TypeVar("_Publisher", bound="GyroPublisher")


def _attitude(d: Dict[str, Any]) -> Attitude:
    return Attitude(**d)


def _health(d: Dict[str, Any]) -> Health:
    d = dict(d)
    d["gyros"] = [GyroStatus(**g) for g in d["gyros"]]
    return Health(**d)


def _event(d: Dict[str, Any]) -> FdiEvent:
    return FdiEvent(**d)


class GyroPublisher:
    """Gyro epochs of ``unit`` on the wire (``GyroSample``), as ``tetra play`` writes them.

    ``gyros``: samples per epoch; ``rate_hz``: the sample rate (the writer offers the deadline of 3 periods,
    which the service's ``sample_rate_hz`` · ``speed`` must allow). ``reference``: also wait for the
    service's reference reader (epochs will carry references). Opening waits up to ``timeout_s`` for
    ``wait_readers`` gyro readers and the service's Health saying it hears this writer (``tetra.Error``
    naming what did not come). With ``lockstep``, each sample says how many the epoch has (flags bits
    24-29) and that its reference was written (bit 31), so the service fuses exactly the epochs sent with
    their references, however slow the caller: use ``Lockstep``.
    """

    def __init__(self, unit: str, gyros: int = 4, rate_hz: float = 100.0, *, domain: Optional[int] = None,
                 lockstep: bool = False, reference: bool = True, wait_readers: int = 1,
                 timeout_s: float = 10.0):
        self._link = _tetra._GyroLink(unit, gyros, rate_hz, domain, lockstep, reference, wait_readers, timeout_s)
        self._open = True

    @property
    def unit(self) -> str:
        return self._link.unit

    @property
    def gyro_count(self) -> int:
        return self._link.gyro_count

    def send(self, time_s: float, raw_V: Any, present: Any = None, reference_q_RB_wxyz: Any = None) -> int:
        """Publishes one epoch: ``raw_V`` (N,) [V] (NaN: an invalid sample), ``present`` (N,) 0/1 (None:
        all; an absent one is not sent), the epoch's reference (4,) or None. ``time_s`` is the sensor time
        (it must increase). Returns the epoch's ``stamp_ns``."""
        return self._link.send(time_s, raw_V, present, reference_q_RB_wxyz)

    def attitudes(self, timeout_s: float = 0.0) -> List[Attitude]:
        """The unit's attitudes received since the last call, oldest first; waits up to ``timeout_s`` for
        one (an empty list then)."""
        return [_attitude(d) for d in self._link.attitudes(timeout_s)]

    def flush(self) -> None:
        """Waits (up to 2 s) until every reader has acknowledged the samples written."""
        self._link.wait_for_acks()

    def close(self) -> None:
        """Flushes (the writers go when the object does)."""
        if self._open:
            self._link.wait_for_acks()
            self._open = False

    def __enter__(self: _Publisher) -> _Publisher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Lockstep(GyroPublisher):
    """A simulator stepping ``tetra fusion`` deterministically: ``step`` publishes one epoch and returns the
    service's Attitude of it (docs/python.md, "DDS"). The attitudes equal ``tetra.Pipeline``'s on the same
    epochs and configuration to the last bit (ctest python_dds). The service's silence deadline
    (3 / (``sample_rate_hz`` · ``speed``) of wall clock) must cover a step of the simulator: give the
    service ``speed: 0.1`` (0.3 s at 100 Hz) for a simulator in Python."""

    def __init__(self, unit: str, gyros: int = 4, rate_hz: float = 100.0, *, domain: Optional[int] = None,
                 reference: bool = True, wait_readers: int = 1, timeout_s: float = 10.0):
        super().__init__(unit, gyros, rate_hz, domain=domain, lockstep=True, reference=reference,
                         wait_readers=wait_readers, timeout_s=timeout_s)

    def step(self, time_s: float, raw_V: Any, present: Any = None, reference_q_RB_wxyz: Any = None,
             timeout_s: float = 2.0) -> Attitude:
        """``send`` and the service's Attitude of this epoch; TimeoutError when none comes within
        ``timeout_s`` (no service, or an epoch it rejected)."""
        return _attitude(self._link.step(time_s, raw_V, present, reference_q_RB_wxyz, timeout_s))


class ReferencePublisher:
    """An attitude reference of its own process (a star tracker): ``send(stamp_ns, q_RB_wxyz)`` writes one
    ``AttitudeReference`` at once, stamped with the sensor time it was taken at. The service fuses one
    that arrives late at its own stamp within its ``reference_horizon_s`` (default 0.5 s); an older one is
    counted (``Health.references_too_late``) and reported (a ``reference_late`` event). Opening waits up to
    ``timeout_s`` for the service's reader (TimeoutError)."""

    def __init__(self, unit: str, *, domain: Optional[int] = None, timeout_s: float = 10.0):
        self._link = _tetra._ReferenceLink(unit, domain, timeout_s)

    def send(self, stamp_ns: int, q_RB_wxyz: Any) -> None:
        self._link.send(int(stamp_ns), q_RB_wxyz)


class Subscriber:
    """The service's outputs for ``unit``: every Attitude, each Health, every FdiEvent (a late joiner gets
    the latest Health and the events so far). ``gyros``: the unit's gyro count (the events' ``json``).

    ``poll(timeout_s)`` takes what arrived (waiting up to ``timeout_s`` for anything) into the queues
    ``attitudes``, ``healths`` and ``events`` (deques, oldest first: pop them as you go);
    ``wait_attitude``, ``wait_health`` and ``wait_event`` return the next one that satisfies a predicate."""

    def __init__(self, unit: str, *, domain: Optional[int] = None, gyros: int = 4):
        self._sub = _tetra._Subscriber(unit, domain, gyros)
        self.unit = unit
        self.attitudes: Deque[Attitude] = deque()
        self.healths: Deque[Health] = deque()
        self.events: Deque[FdiEvent] = deque()

    def poll(self, timeout_s: float = 0.0) -> int:
        """Takes every sample received (waiting up to ``timeout_s`` for one); returns how many came."""
        attitudes, healths, events = self._sub.take_all(timeout_s)
        self.attitudes.extend(_attitude(d) for d in attitudes)
        self.healths.extend(_health(d) for d in healths)
        self.events.extend(_event(d) for d in events)
        return len(attitudes) + len(healths) + len(events)

    def wait_attitude(self, timeout_s: float, where: Optional[Callable[[Attitude], bool]] = None) -> Attitude:
        """The oldest queued Attitude (for which ``where`` is true; those before it are dropped)."""
        return self._wait(self.attitudes, "Attitude", timeout_s, where)

    def wait_health(self, timeout_s: float, where: Optional[Callable[[Health], bool]] = None) -> Health:
        return self._wait(self.healths, "Health", timeout_s, where)

    def wait_event(self, timeout_s: float, where: Optional[Callable[[FdiEvent], bool]] = None) -> FdiEvent:
        return self._wait(self.events, "FdiEvent", timeout_s, where)

    def _wait(self, queue: Deque[Any], what: str, timeout_s: float, where: Optional[Callable[[Any], bool]]) -> Any:
        import time
        give_up = time.monotonic() + timeout_s
        while True:
            while queue:
                item = queue.popleft()
                if where is None or where(item):
                    return item
            left = give_up - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"no {what} of unit '{self.unit}'"
                                   f"{' matching the condition' if where else ''} within {timeout_s:g} s")
            self.poll(min(left, 0.5))


def command(unit: str, action: str, gyro: Optional[int] = None, *, force: bool = False,
            domain: Optional[int] = None, timeout_s: float = 5.0, operator: Optional[str] = None,
            origin: Optional[str] = None, gyros: int = 4) -> FdiEvent:
    """An operator command as ``tetra command`` sends it: ``action`` reset, exclude or reinstate (``gyro``
    1..N for the last two; ``force``: exclude even if the unit could then no longer determine attitude).
    Returns the acknowledgement (``refused`` True: refused, ``detail`` says why). TimeoutError when no
    service or no acknowledgement comes within ``timeout_s``; BadInputError for a malformed command. The
    wait is bounded by ``timeout_s`` (Ctrl-C is taken when it returns). ``operator`` defaults to the login
    name, ``origin`` to ``python@HOSTNAME``."""
    return _event(_tetra._command(unit, action, gyro or 0, force, operator or getpass.getuser(),
                                  origin or "python@" + socket.gethostname(), domain, timeout_s, gyros))

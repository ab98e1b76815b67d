"""tetra from Python: calibration, Allan analysis, simulation, the fusion and fault-detection pipeline,
scoring and fault-injection campaigns of redundant gyro packages (docs/python.md).

The work is done by tetra's C++ libraries (tetra::core, tetra::fdi, tetra::sim) through the module
``tetra._tetra``; this package adds the Python conveniences (paths or arrays or dicts in, pandas frames out).

Arrays: float64 C-contiguous arrays are read in place (no copy); any other real dtype or a strided view is
converted once (one copy). Results are numpy arrays that own the library's memory (no copy either).
numpy is imported when first needed (``import tetra`` alone does not need it).
Errors: the library's messages raise ``tetra.BadInputError`` (bad input: a ValueError) or ``tetra.Error``
(other failures); arguments of the wrong shape or dtype raise ValueError or TypeError naming the argument.
Warnings (``tetra.DefaultNoiseWarning``) go through Python's ``warnings``.
Long calls (``Pipeline.run``, ``run_log``, ``sim``, ``allan``, ``campaign``) stop on Ctrl-C within a few
milliseconds (KeyboardInterrupt) and take ``progress=``: a callable ``progress(done, total)`` or a tqdm bar.
DDS: ``import tetra.dds`` puts a simulator on the wire to a ``tetra fusion`` service (lockstep included).
"""
from __future__ import annotations

import json
import math
import numbers
import os
import warnings
from typing import Any, Callable, Mapping, Optional, Sequence, Union

from . import _tetra
from ._tetra import (
    MODE_NAMES,
    ONE_SIGMA_CONFIDENCE,
    AllanResult,
    AttitudeScore,
    BadInputError,
    Calibration,
    CalibrationResult,
    CampaignSpec,
    Error,
    GyroAllan,
    GyroLog,
    LogAllan,
    NoiseFit,
    PipelineConfig,
    Scenario,
    SimRun,
    Truth,
    builtin_scenarios,
    read_gyro_log,
)

__version__ = _tetra.__version__

__all__ = [
    "AllanResult", "AttitudeScore", "BadInputError", "Calibration", "CalibrationResult", "CampaignResult",
    "CampaignSpec", "DefaultNoiseWarning", "Error", "GyroAllan", "GyroLog", "LogAllan", "MODE_NAMES", "NoiseFit", "ONE_SIGMA_CONFIDENCE",
    "Pipeline", "PipelineConfig", "PipelineRun", "Scenario", "SimRun", "Truth", "allan", "allan_log",
    "builtin_scenarios", "calibrate", "campaign", "campaign_spec", "log_frame", "pipeline_config",
    "oadev", "read_gyro_log", "scenario", "score", "sim", "simulate_turntable", "truth_frame",
]


class DefaultNoiseWarning(UserWarning):
    """A gyro of the calibration has no ``noise:`` section: fault detection runs on conservative default
    noise figures (the warning ``tetra replay`` prints; ``tetra allan --update-calibration`` measures them)."""

PathLike = Union[str, "os.PathLike[str]"]
_RAD_TO_DEG = 180.0 / math.pi  # the libraries' kRadToDeg: the same double


def _is_path(value: Any) -> bool:
    return isinstance(value, (str, os.PathLike))


def _progress(progress: Any) -> Any:
    """``progress=`` as the callable the module calls with (done, total): None, a callable, a tqdm-like
    bar (an object with ``update(n)``: its ``total`` is set when it has none, and it is advanced by the
    work done since the last call), or such a bar's class (``progress=tqdm``: a bar made for the call and
    closed at its end)."""
    if progress is None or (callable(progress) and not hasattr(progress, "update")):
        return progress
    if not hasattr(progress, "update"):
        raise TypeError("progress: expected None, a callable progress(done, total) or a tqdm bar")
    own = isinstance(progress, type)
    bar = progress() if own else progress
    reported = [0]

    def advance(done: int, total: int) -> None:
        if getattr(bar, "total", None) in (None, 0) and total:
            bar.total = total
            if hasattr(bar, "refresh"):
                bar.refresh()
        if done > reported[0]:
            bar.update(done - reported[0])
            reported[0] = done
        if own and total and done >= total:
            bar.close()
    return advance


def _yaml_text(mapping: Mapping[str, Any], what: str) -> str:
    """A dict as YAML text (JSON is YAML): the library reads it as it reads a file."""
    try:
        return json.dumps(mapping, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{what}: the dict must hold only numbers, text, lists and dicts ({e})") from None


# --- calibration ------------------------------------------------------------------------------------

_TURNTABLE_KEYS = ("sequence", "time_s", "inner_deg", "outer_deg", "g_V")


def calibrate(turntable: Union[PathLike, Mapping[str, Any]], *, latitude_deg: Optional[float] = None,
              method: str = "sixteen", bias_model: str = "body", unit: Optional[str] = None,
              noise: Optional[Calibration] = None,
              bias_instability_correlation_s: float = 100.0) -> CalibrationResult:
    """Turntable calibration (``tetra calibrate``): scale factor, bias and axis of every gyro with their 1σ.

    ``turntable`` is a turntable log file (docs/interfaces.md §2.1; read a block at a time, as the command
    reads it) or a mapping of arrays ``sequence`` (n,), ``time_s`` (n,), ``inner_deg`` (n,), ``outer_deg``
    (n,) and ``g_V`` (n, N), read in place when float64 C-contiguous. ``latitude_deg`` [deg] defaults to the
    file's ``# latitude_deg=`` comment (required with arrays). ``method``: 'sixteen' or 'batch';
    ``bias_model``: 'body' or 'seed' (sixteen only). ``noise``: a calibration whose gyros carry ``noise:``
    sections, for honest 1σ. The GIL is released while the library works.
    """
    if _is_path(turntable):
        return _tetra._calibrate_file(os.fspath(turntable), latitude_deg, method, bias_model, unit, noise,
                                      bias_instability_correlation_s)
    if not isinstance(turntable, Mapping):
        raise TypeError("turntable: expected a file name or a mapping of arrays " + ", ".join(_TURNTABLE_KEYS))
    missing = [k for k in _TURNTABLE_KEYS if k not in turntable]
    if missing:
        raise ValueError("turntable: missing arrays " + ", ".join(missing))
    if latitude_deg is None:
        latitude_deg = turntable.get("latitude_deg")
    if latitude_deg is None:
        raise ValueError("latitude_deg: required with arrays (the latitude of the turntable [deg])")
    return _tetra._calibrate_arrays(*(turntable[k] for k in _TURNTABLE_KEYS), float(latitude_deg), method,
                                    bias_model, unit, noise, bias_instability_correlation_s)


def simulate_turntable(unit: Optional[Calibration] = None, *, table_rate_dps: float = 6.0,
                       revolutions: float = 1.0, rate_hz: float = 10.0, latitude_deg: float = -23.2,
                       seed: int = 1) -> dict:
    """The 16-sequence rotation plan of seed Table 3 simulated (``tetra sim turntable``) for ``unit`` (the
    seed's unit as built by default): a dict of arrays ``sequence``, ``time_s``, ``inner_deg``,
    ``outer_deg``, ``g_V`` (n, N), with ``latitude_deg``, ``metadata`` and ``text`` (the log file's text)."""
    d = _tetra._simulate_turntable(unit if unit is not None else Calibration.seed_unit(), table_rate_dps,
                                   revolutions, rate_hz, latitude_deg, seed)
    d["latitude_deg"] = latitude_deg
    return d


# --- Allan ------------------------------------------------------------------------------------------

Taus = Union[str, Sequence[float]]


def _taus(taus: Taus) -> Union[str, list]:
    return taus if isinstance(taus, str) else [float(t) for t in taus]


def allan(data: Any = None, tau0_s: Optional[float] = None, *, rate: Any = None, present: Any = None,
          taus: Taus = "default", confidence: float = ONE_SIGMA_CONFIDENCE,
          progress: Any = None) -> Union[AllanResult, list]:
    """Overlapping Allan deviation, confidence intervals and the IEEE 952 noise terms of uniformly sampled
    rate data (``tetra allan``'s analysis). ``data``: shape (n,) — or (n, k) for k series, giving a list —
    in any unit (the terms come in it); NaN or ``present`` == 0 (any nonzero: present) marks a sample not
    delivered; ``present`` is shaped like ``data``, or (n,) for every series of a 2-D ``data``.
    ``tau0_s`` [s]: the sampling interval, or ``rate`` [Hz] the sampling rate (as allantools takes it).
    ``taus``: 'default', 'octave', 'decade', 'all' or a list of τ [s]. ``progress``: see the package's
    docstring (averaging times done). ``tetra.oadev`` (also ``tetra.allan.oadev``) is allantools' call.

    (``rate=`` given an array instead of a number is the data: ``allan(rate=y, tau0_s=0.1)`` still works.)
    """
    import numpy as np
    if rate is not None and not isinstance(rate, numbers.Real):
        if data is not None:
            raise TypeError("allan: data given twice (data and rate=; rate= is the sampling rate [Hz])")
        data, rate = rate, None
    if data is None:
        raise TypeError("allan: missing the data (the rate samples)")
    tau0_s = _sampling_interval(tau0_s, rate)
    t = _taus(taus)
    report = _progress(progress)
    arr = np.asarray(data)
    if arr.ndim == 2:
        pres = None if present is None else np.asarray(present)
        if pres is not None and pres.shape not in (arr.shape, arr.shape[:1]):
            raise ValueError(f"present: expected shape {arr.shape} like data, or ({arr.shape[0]},) for every "
                             f"series, got {pres.shape}")

        def column_present(j: int) -> Any:
            if pres is None:
                return None
            return pres if pres.ndim == 1 else np.ascontiguousarray(pres[:, j])
        def column_report(j: int) -> Any:  # the series one after the other: (done, total) over all of them
            k = arr.shape[1]
            return None if report is None else (lambda done, total: report(j * total + done, k * total))
        return [_tetra._allan_series(np.ascontiguousarray(arr[:, j], dtype=np.float64), tau0_s,
                                     column_present(j), t, confidence, column_report(j))
                for j in range(arr.shape[1])]
    return _tetra._allan_series(data, tau0_s, present, t, confidence, report)


def _sampling_interval(tau0_s: Optional[float], rate: Optional[float]) -> float:
    if (tau0_s is None) == (rate is None):
        raise TypeError("allan: give the sampling interval tau0_s [s] or the sampling rate rate= [Hz], one of them")
    if rate is not None:
        if not (math.isfinite(rate) and rate > 0):
            raise ValueError("rate: the sampling rate [Hz] must be a positive number")
        return 1.0 / float(rate)
    return float(tau0_s)  # type: ignore[arg-type]


def oadev(data: Any, rate: float = 1.0, data_type: str = "phase", taus: Any = None) -> tuple:
    """Overlapping Allan deviation as allantools' ``oadev`` gives it: ``(taus, devs, errs, ns)``, numpy
    arrays (errs = devs/√ns, ns as floats), computed by tetra's library. ``data``: 1-D, 'phase' (angle or
    time: the integral of the rate) or 'freq' (rate) samples at ``rate`` [Hz]; ``taus``: None or 'octave'
    (2^k τ0), 'decade' (1, 2, 4 × 10^k τ0), 'all', or τ values [s] (each rounded to a multiple of τ0).
    Averaging times are kept, as allantools keeps them, where at least two second differences exist. A NaN
    sample is a gap (allantools lets it propagate). For the confidence intervals and the noise terms, use
    ``tetra.allan``."""
    import numpy as np
    if data_type not in ("phase", "freq"):
        raise ValueError(f"data_type: expected 'phase' or 'freq', got {data_type!r}")
    if not (isinstance(rate, numbers.Real) and math.isfinite(rate) and rate > 0):
        raise ValueError("rate: the sampling rate [Hz] must be a positive number")
    x = np.asarray(data, dtype=np.float64)
    if x.ndim != 1:
        raise ValueError(f"data: expected a 1-D array, got shape {x.shape}")
    y = np.diff(x) * rate if data_type == "phase" else x
    phase_points = len(y) + 1
    if isinstance(taus, str) or taus is None:
        spacing = "octave" if taus is None else taus
        if spacing == "all":
            m = np.arange(1, phase_points + 1, dtype=np.float64)
        elif spacing == "octave":
            m = 2.0 ** np.arange(int(np.floor(np.log2(phase_points))) + 1)
        elif spacing == "decade":
            m = np.array([f * 10.0 ** k for k in range(int(np.floor(np.log10(phase_points))) + 1)
                          for f in (1.0, 2.0, 4.0)])
        else:
            raise ValueError(f"taus: expected None, 'octave', 'decade', 'all' or averaging times [s], got {taus!r}")
    else:
        m = np.round(np.asarray(taus, dtype=np.float64) * rate)
    # allantools' tau_generator and remove_small_ns: 0 < m < N phase points, at least 2 terms (N - 2m).
    m = np.unique(m[(m > 0) & (m < phase_points) & (phase_points - 2 * m >= 2)])
    if len(m) == 0:
        empty = np.zeros(0)
        return empty, empty.copy(), empty.copy(), empty.copy()
    r = _tetra._allan_series(np.ascontiguousarray(y), 1.0 / rate, None, [float(k) / rate for k in m],
                             ONE_SIGMA_CONFIDENCE, None)
    ns = np.asarray(r.terms, dtype=np.float64)
    devs = np.array(r.adev)
    return np.array(r.tau_s), devs, devs / np.sqrt(ns), ns


allan.oadev = oadev  # type: ignore[attr-defined]


def allan_log(path: PathLike, *, calibration: Optional[Calibration] = None,
              gyros: Sequence[int] = (), taus: Taus = "default", confidence: float = ONE_SIGMA_CONFIDENCE,
              dt_tolerance: float = 0.05) -> LogAllan:
    """``tetra allan`` on a gyro log file (CSV or HDF5): every gyro (or ``gyros``), volts turned into deg/s
    with ``calibration``. ``LogAllan.to_csv()``/``to_json()`` give the command's files."""
    return _tetra._allan_log(os.fspath(path), calibration, list(gyros), _taus(taus), confidence, dt_tolerance)


# --- simulation -------------------------------------------------------------------------------------

def scenario(spec: Union[str, PathLike, Mapping[str, Any], Scenario], *, duration_s: Optional[float] = None,
             rate_hz: Optional[float] = None, base_dir: Optional[PathLike] = None) -> Scenario:
    """A scenario (docs/sim.md): a built-in name (``builtin_scenarios()``), a YAML file, or a dict with the
    file's keys (``unit:`` paths resolved against ``base_dir``, the working directory by default)."""
    if isinstance(spec, Scenario):
        sc = spec
    elif isinstance(spec, Mapping):
        sc = _tetra._parse_scenario(_yaml_text(spec, "scenario"), "scenario dict",
                                    os.fspath(base_dir) if base_dir is not None else os.getcwd())
    elif isinstance(spec, str) and spec in builtin_scenarios():
        sc = _tetra._builtin_scenario(spec)
    elif _is_path(spec):
        sc = _tetra._read_scenario(os.fspath(spec))
    else:
        raise TypeError("scenario: expected a built-in name, a file name, a dict or a tetra.Scenario")
    if duration_s is not None:
        sc.duration_s = float(duration_s)
    if rate_hz is not None:
        sc.rate_hz = float(rate_hz)
    return sc


def sim(spec: Union[str, PathLike, Mapping[str, Any], Scenario], *, seed: int = 1,
        duration_s: Optional[float] = None, rate_hz: Optional[float] = None, progress: Any = None) -> SimRun:
    """Simulates a scenario (``tetra sim``): its gyro log (``.log``, a GyroLog in volts, with reference
    columns when the scenario has a reference) and its truth (``.truth``), as numpy arrays; the same seed
    gives the same numbers, bit for bit, as ``tetra sim``'s files. ``log_frame``/``truth_frame`` make
    pandas frames of them. ``progress``: see the package's docstring (epochs simulated). Ctrl-C stops it
    (KeyboardInterrupt; nothing is kept)."""
    return _tetra._simulate(scenario(spec, duration_s=duration_s, rate_hz=rate_hz), seed, _progress(progress))


def log_frame(log: GyroLog):
    """A gyro log as a pandas DataFrame: time_s, g1..gN (NaN where absent), and qw, qx, qy, qz of the
    reference (NaN where none) when the log has one."""
    import pandas as pd
    cols = {"time_s": log.time_s}
    for i in range(log.gyro_count):
        cols[f"g{i + 1}"] = log.values[:, i]
    if log.reference_wxyz is not None:
        for j, name in enumerate(("ref_qw", "ref_qx", "ref_qy", "ref_qz")):
            cols[name] = log.reference_wxyz[:, j]
    return pd.DataFrame(cols)


def _truth_rate_dps(truth: Truth):
    return truth.omega_BR_B_rad_s * _RAD_TO_DEG + 0.0  # as the truth file writes it (no -0)


def truth_frame(truth: Truth):
    """The truth as a pandas DataFrame with the columns of ``tetra sim --truth``:
    time_s, qw, qx, qy, qz, wx_dps, wy_dps, wz_dps."""
    import pandas as pd
    w = _truth_rate_dps(truth)
    q = truth.q_RB_wxyz
    return pd.DataFrame({"time_s": truth.time_s, "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2], "qz": q[:, 3],
                         "wx_dps": w[:, 0], "wy_dps": w[:, 1], "wz_dps": w[:, 2]})


# --- the pipeline -----------------------------------------------------------------------------------

def pipeline_config(config: Union[None, PathLike, Mapping[str, Any], PipelineConfig] = None) -> PipelineConfig:
    """The pipeline's configuration (docs/fdi.md): defaults (None), a YAML file with a ``pipeline:`` map, a
    dict of that map's keys (e.g. ``{"latitude_deg": 45.0}``), or a PipelineConfig."""
    if config is None:
        return PipelineConfig()
    if isinstance(config, PipelineConfig):
        return config
    if isinstance(config, Mapping):
        return _tetra._parse_pipeline_config(_yaml_text({"pipeline": dict(config)}, "config"), "config dict")
    if _is_path(config):
        return _tetra._read_pipeline_config(os.fspath(config))
    raise TypeError("config: expected None, a file name, a dict or a tetra.PipelineConfig")


class PipelineRun:
    """What ``Pipeline.run`` made of the epochs: one row per accepted epoch, in the units and with the
    arithmetic of ``tetra replay --attitude`` (equal to that file's numbers to the last bit), and the events.

    Arrays: ``time_s`` (m,), ``q_RB_wxyz`` (m, 4), ``omega_BR_B_dps`` (m, 3), ``sigma_deg`` (m,) (1σ of the
    total angle), ``sigma_B_deg`` (m, 3), ``bias_dps`` (m, N), ``protection_level_B_deg`` (m, 3), ``mode``
    (m,) uint8 indices into ``MODE_NAMES``, ``gyros`` (m,) uint32 masks (bit i−1: gyro i used),
    ``fdi_available`` (m,) uint8. ``events``: dicts (type, gyro, test, ..., json: the line of
    ``tetra replay --events``). ``epochs``: epochs given.
    """

    def __init__(self, d: dict, gyro_count: int):
        self.__dict__.update(d)
        self.gyro_count = gyro_count

    def __len__(self) -> int:
        return len(self.time_s)

    def __repr__(self) -> str:
        return f"<tetra.PipelineRun epochs={self.epochs} accepted={len(self)} events={len(self.events)}>"

    @property
    def mode_names(self):
        """The mode of each row as text (NOMINAL, DEGRADED, SUSPECT, LOST), a numpy array."""
        import numpy as np
        return np.asarray(MODE_NAMES, dtype=object)[self.mode]

    def attitude_frame(self):
        """The rows as a pandas DataFrame with the columns of ``tetra replay --attitude`` (the gyros used as
        the mask ``gyros_mask``)."""
        import pandas as pd
        cols = {"time_s": self.time_s}
        for j, name in enumerate(("qw", "qx", "qy", "qz")):
            cols[name] = self.q_RB_wxyz[:, j]
        for j, name in enumerate(("wx_dps", "wy_dps", "wz_dps")):
            cols[name] = self.omega_BR_B_dps[:, j]
        cols["sigma_deg"] = self.sigma_deg
        cols["mode"] = self.mode_names
        cols["gyros_mask"] = self.gyros
        for j, name in enumerate(("sigma_x_deg", "sigma_y_deg", "sigma_z_deg")):
            cols[name] = self.sigma_B_deg[:, j]
        for i in range(self.gyro_count):
            cols[f"bias_{i + 1}_dps"] = self.bias_dps[:, i]
        for j, name in enumerate(("pl_x_deg", "pl_y_deg", "pl_z_deg")):
            cols[name] = self.protection_level_B_deg[:, j]
        return pd.DataFrame(cols)

    def events_frame(self):
        """The events as a pandas DataFrame (one row per event; columns as the event dicts' keys)."""
        import pandas as pd
        return pd.DataFrame(self.events, columns=["stamp_ns", "time_s", "type", "gyro", "test", "statistic",
                                                  "kind", "evidence", "gyros", "command", "outcome", "why",
                                                  "detail", "json"])


class Pipeline:
    """The fusion and fault-detection pipeline (docs/fdi.md), the object ``tetra replay`` and the
    ``tetra fusion`` service run: raw gyro epochs in; attitude, 1σ, mode and FDI events out.

    ``calibration``: a Calibration (or a file name); ``config``: see ``pipeline_config``; ``units_dps``: the
    samples are rates [deg/s] (a log with ``# units=dps``) rather than volts. A calibration without
    ``noise:`` sections gives a ``DefaultNoiseWarning`` (``warnings``), as ``tetra replay`` warns.

    Threads: a Pipeline serves one call at a time. A call made while another runs on it (from another
    thread, or from a run's progress callback) raises RuntimeError; give each thread its own Pipeline.
    """

    def __init__(self, calibration: Union[Calibration, PathLike],
                 config: Union[None, PathLike, Mapping[str, Any], PipelineConfig] = None, *,
                 units_dps: bool = False):
        self.calibration = calibration if isinstance(calibration, Calibration) else Calibration.read(
            os.fspath(calibration))
        self._p = _tetra._Pipeline(self.calibration, pipeline_config(config), units_dps)
        warning = self._p.default_noise_warning(self.calibration)
        if warning:
            warnings.warn(warning, DefaultNoiseWarning, stacklevel=2)

    @property
    def gyro_count(self) -> int:
        return self._p.gyro_count

    @property
    def config(self) -> PipelineConfig:
        return self._p.config

    def step(self, time_s: float, raw: Any, present: Any = None, reference_wxyz: Any = None) -> dict:
        """One epoch: ``raw`` (N,) samples [V or deg/s] (NaN: invalid), ``present`` (N,) 0 where no sample
        was delivered, ``reference_wxyz`` (4,) an attitude reference or None. Returns a dict: accepted,
        attitude (a dict, None when the epoch was rejected) and events (list of dicts)."""
        import numpy as np
        t = np.asarray([time_s], dtype=np.float64)
        r = np.asarray(raw, dtype=np.float64).reshape(1, -1)
        p = None if present is None else np.asarray(present).reshape(1, -1)
        q = None if reference_wxyz is None else np.asarray(reference_wxyz, dtype=np.float64).reshape(1, -1)
        return self._p.step(t, r, p, q)

    def run(self, time_s: Any, raw: Any, present: Any = None, reference_wxyz: Any = None,
            reference_present: Any = None, *, progress: Any = None) -> PipelineRun:
        """Every epoch in C++ (no Python per epoch; the GIL released): ``time_s`` (n,), ``raw`` (n, N),
        ``present`` (n, N) or None (all delivered; any nonzero is present), ``reference_wxyz`` (n, 4) with
        NaN rows where there is no reference (or ``reference_present`` (n,)). float64 C-contiguous arrays
        are read in place. ``progress``: see the package's docstring (epochs done).

        Ctrl-C raises KeyboardInterrupt within a few milliseconds; the rows made so far are dropped and the
        pipeline keeps the state of the epochs it stepped (``reset()`` to start again)."""
        return PipelineRun(self._p.run(time_s, raw, present, reference_wxyz, reference_present,
                                       _progress(progress)), self.gyro_count)

    def run_log(self, log: GyroLog, *, progress: Any = None) -> PipelineRun:
        """``run`` over a GyroLog (``read_gyro_log``, ``sim(...).log``), as ``tetra replay`` runs a file."""
        return self.run(log.time_s, log.values, log.present, log.reference_wxyz, log.reference_present,
                        progress=progress)

    def reset(self) -> None:
        """Back to the initial state (all gyros reinstated, the configured initial attitude)."""
        self._p.reset()

    def health(self) -> dict:
        """Mode, gyros used, per-gyro state, detector statistics and the counters."""
        return self._p.health()

    def exclude(self, gyro: int, stamp_ns: int, force: bool = False) -> dict:
        """Operator command: leave gyro out; returns the acknowledgement event."""
        return self._p.exclude(gyro, stamp_ns, force)

    def reinstate(self, gyro: int, stamp_ns: int) -> dict:
        """Operator command: use an excluded gyro again; returns the acknowledgement event."""
        return self._p.reinstate(gyro, stamp_ns)

    def reset_command(self, stamp_ns: int) -> dict:
        """Operator command: reset; returns the acknowledgement event."""
        return self._p.reset_command(stamp_ns)

    def describe_thresholds(self) -> str:
        """The thresholds derived from the configuration and the calibration (``tetra replay -v``)."""
        return self._p.describe_thresholds()


# --- score ------------------------------------------------------------------------------------------

def _series(value: Any, with_sigma: bool, what: str):
    if _is_path(value):
        return _tetra._read_attitude_series(os.fspath(value), with_sigma)
    if isinstance(value, PipelineRun):
        return _tetra._attitude_series(what, value.time_s, value.q_RB_wxyz, value.omega_BR_B_dps,
                                       value.sigma_deg, value.sigma_B_deg)
    if isinstance(value, SimRun):
        value = value.truth
    if isinstance(value, Truth):
        return _tetra._attitude_series(what, value.time_s, value.q_RB_wxyz, _truth_rate_dps(value), None, None)
    if isinstance(value, Mapping):
        return _tetra._attitude_series(what, value["time_s"], value["q_RB_wxyz"], value["omega_BR_B_dps"],
                                       value.get("sigma_deg") if with_sigma else None,
                                       value.get("sigma_B_deg") if with_sigma else None)
    if hasattr(value, "columns") and hasattr(value, "to_numpy"):
        return _frame_series(value, with_sigma, what)
    raise TypeError(f"{what}: expected a file name, a PipelineRun, a Truth/SimRun, a DataFrame with the "
                    "columns of the attitude or truth file, or a mapping of arrays")


_FRAME_Q = ["qw", "qx", "qy", "qz"]
_FRAME_W = ["wx_dps", "wy_dps", "wz_dps"]
_FRAME_SIGMA_B = ["sigma_x_deg", "sigma_y_deg", "sigma_z_deg"]


def _frame_series(frame: Any, with_sigma: bool, what: str) -> Any:
    """A pandas DataFrame with the columns of ``tetra replay --attitude`` (``PipelineRun.attitude_frame()``)
    or ``tetra sim --truth`` (``truth_frame()``)."""
    import numpy as np
    columns = set(frame.columns)
    missing = [c for c in ["time_s", *_FRAME_Q, *_FRAME_W] if c not in columns]
    if missing:
        raise ValueError(f"{what}: the DataFrame lacks the columns " + ", ".join(missing))

    def block(names: list) -> Any:
        return np.ascontiguousarray(frame[names].to_numpy(dtype=np.float64))
    sigma = sigma_b = None
    if with_sigma and "sigma_deg" in columns:
        sigma = np.ascontiguousarray(frame["sigma_deg"].to_numpy(dtype=np.float64))
    if with_sigma and columns.issuperset(_FRAME_SIGMA_B):
        sigma_b = block(_FRAME_SIGMA_B)
    return _tetra._attitude_series(what, np.ascontiguousarray(frame["time_s"].to_numpy(dtype=np.float64)),
                                   block(_FRAME_Q), block(_FRAME_W), sigma, sigma_b)


def score(attitude: Any, truth: Any, *, time_tolerance_s: float = 1e-6,
          axis_B: Sequence[float] = (0.0, 1.0, 0.0)) -> AttitudeScore:
    """``tetra score``: an attitude estimate (a ``tetra replay --attitude`` file, a PipelineRun, its
    ``attitude_frame()``, or a mapping of time_s, q_RB_wxyz, omega_BR_B_dps, sigma_deg[, sigma_B_deg])
    against the truth (a ``tetra sim --truth`` file, a Truth or SimRun, ``truth_frame()``, or a mapping of
    time_s, q_RB_wxyz, omega_BR_B_dps)."""
    return _tetra._score(_series(attitude, True, "attitude"), _series(truth, False, "truth"),
                         float(time_tolerance_s), [float(a) for a in axis_B])


# --- campaigns --------------------------------------------------------------------------------------

def campaign_spec(spec: Union[PathLike, Mapping[str, Any], CampaignSpec], *,
                  base_dir: Optional[PathLike] = None) -> CampaignSpec:
    """A campaign spec (docs/campaign.md) from a YAML file or a dict with the file's keys (scenario files
    resolved against ``base_dir``, the working directory by default); checked whole before anything runs."""
    if isinstance(spec, CampaignSpec):
        return spec
    if isinstance(spec, Mapping):
        return _tetra._parse_campaign_spec(_yaml_text(spec, "spec"), "campaign dict",
                                           os.fspath(base_dir) if base_dir is not None else os.getcwd())
    if _is_path(spec):
        return _tetra._read_campaign_spec(os.fspath(spec))
    raise TypeError("spec: expected a file name, a dict or a tetra.CampaignSpec")


class CampaignResult:
    """The rows of a campaign: ``rows`` (a pandas DataFrame with the columns of runs.csv), ``csv`` (the
    text of runs.csv for these runs, byte for byte what ``tetra campaign`` writes, in run order) and
    ``report`` (report.md for these runs, byte for byte ``tetra campaign``'s; its plots are drawn by the
    command, or from ``rows`` with matplotlib)."""

    def __init__(self, csv: str, report: Union[str, Callable[[str], str]] = ""):
        self.csv = csv
        self._report = report
        self._rows = None

    @property
    def rows(self):
        """The rows as a pandas DataFrame (the columns of runs.csv; made at the first access)."""
        if self._rows is None:
            import io

            import pandas as pd
            # round_trip: the rows' shortest round-trip numbers read back to the same doubles
            self._rows = pd.read_csv(io.StringIO(self.csv), float_precision="round_trip",
                                     dtype={"scenario": str, "kind": str, "outcome": str})
        return self._rows

    @property
    def report(self) -> str:
        """report.md for these runs (made at the first access)."""
        if callable(self._report):
            self._report = self._report(self.csv)
        return self._report

    def __len__(self) -> int:
        return self.csv.count("\n") - 1

    def __repr__(self) -> str:
        return f"<tetra.CampaignResult runs={len(self)}>"


def campaign(spec: Union[PathLike, Mapping[str, Any], CampaignSpec], *, runs: Optional[Sequence[int]] = None,
             base_dir: Optional[PathLike] = None, jobs: int = 1, progress: Any = None) -> CampaignResult:
    """Runs a campaign in process (``tetra campaign`` with ``target: in_process``) with the GIL released:
    every run of the matrix, or the run ids ``runs`` (each once); a run that fails is an error row, as
    ``tetra campaign`` writes it. ``jobs``: runs at a time, in threads of this process (``os.cpu_count()``
    for all cores); the rows are the same whatever ``jobs``. ``progress``: see the package's docstring
    (runs done). The result's ``report`` is ``tetra campaign``'s report.md.

    Ctrl-C raises KeyboardInterrupt within a few milliseconds; the runs under way are dropped and the
    exception's ``partial`` is the CampaignResult of the runs done, so that
    ``campaign(spec, runs=[r for r in range(campaign_spec(spec).runs) if r not in set(e.partial.rows.run)])``
    continues, as ``tetra campaign`` resumes."""
    s = campaign_spec(spec, base_dir=base_dir)
    lines, stopped = _tetra._campaign_rows(s, None if runs is None else [int(r) for r in runs], int(jobs),
                                           _progress(progress))
    csv = _tetra._campaign_csv_header(s) + "\n" + "".join(line + "\n" for line in lines)
    result = CampaignResult(csv, lambda text: _tetra._campaign_report(s, text))
    if stopped is not None:
        stopped.partial = result
        raise stopped
    return result

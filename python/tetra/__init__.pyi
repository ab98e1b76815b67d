# Type stubs of the package tetra (docs/python.md): editors complete from these.
import os
from typing import Any, Callable, Mapping, Optional, Protocol, Sequence, Union

import numpy as np
import numpy.typing as npt
import pandas

from ._tetra import (
    MODE_NAMES as MODE_NAMES,
    ONE_SIGMA_CONFIDENCE as ONE_SIGMA_CONFIDENCE,
    AllanResult as AllanResult,
    AttitudeScore as AttitudeScore,
    BadInputError as BadInputError,
    Calibration as Calibration,
    CalibrationResult as CalibrationResult,
    CampaignSpec as CampaignSpec,
    Error as Error,
    GyroAllan as GyroAllan,
    GyroLog as GyroLog,
    LogAllan as LogAllan,
    NoiseFit as NoiseFit,
    PipelineConfig as PipelineConfig,
    Scenario as Scenario,
    SimRun as SimRun,
    Truth as Truth,
    builtin_scenarios as builtin_scenarios,
    read_gyro_log as read_gyro_log,
)

__version__: str

class DefaultNoiseWarning(UserWarning): ...

class _Bar(Protocol):
    def update(self, n: int) -> object: ...

#: progress=: a callable progress(done, total), a tqdm-like bar (an object with update(n)) or its class.
_ProgressLike = Union[None, Callable[[int, int], object], _Bar, type[_Bar]]
PathLike = Union[str, os.PathLike[str]]
Taus = Union[str, Sequence[float]]
_ConfigLike = Union[None, PathLike, Mapping[str, Any], PipelineConfig]
_ScenarioLike = Union[str, PathLike, Mapping[str, Any], Scenario]

def calibrate(turntable: Union[PathLike, Mapping[str, Any]], *, latitude_deg: Optional[float] = ...,
              method: str = ..., bias_model: str = ..., unit: Optional[str] = ...,
              noise: Optional[Calibration] = ...,
              bias_instability_correlation_s: float = ...) -> CalibrationResult: ...
def simulate_turntable(unit: Optional[Calibration] = ..., *, table_rate_dps: float = ..., revolutions: float = ...,
                       rate_hz: float = ..., latitude_deg: float = ..., seed: int = ...) -> dict[str, Any]: ...
class _Allan(Protocol):
    def __call__(self, data: Optional[npt.ArrayLike] = ..., tau0_s: Optional[float] = ..., *,
                 rate: Union[None, float, npt.ArrayLike] = ..., present: Optional[npt.ArrayLike] = ...,
                 taus: Taus = ..., confidence: float = ...,
                 progress: _ProgressLike = ...) -> Union[AllanResult, list[AllanResult]]: ...
    @staticmethod
    def oadev(data: npt.ArrayLike, rate: float = ..., data_type: str = ...,
              taus: Union[None, str, npt.ArrayLike] = ...) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64],
                                                                   npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

allan: _Allan
def oadev(data: npt.ArrayLike, rate: float = ..., data_type: str = ...,
          taus: Union[None, str, npt.ArrayLike] = ...) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64],
                                                               npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def allan_log(path: PathLike, *, calibration: Optional[Calibration] = ..., gyros: Sequence[int] = ...,
              taus: Taus = ..., confidence: float = ..., dt_tolerance: float = ...) -> LogAllan: ...
def scenario(spec: _ScenarioLike, *, duration_s: Optional[float] = ..., rate_hz: Optional[float] = ...,
             base_dir: Optional[PathLike] = ...) -> Scenario: ...
def sim(spec: _ScenarioLike, *, seed: int = ..., duration_s: Optional[float] = ...,
        rate_hz: Optional[float] = ..., progress: _ProgressLike = ...) -> SimRun: ...
def log_frame(log: GyroLog) -> pandas.DataFrame: ...
def truth_frame(truth: Truth) -> pandas.DataFrame: ...
def pipeline_config(config: _ConfigLike = ...) -> PipelineConfig: ...

class PipelineRun:
    def __init__(self, d: dict[str, Any], gyro_count: int) -> None: ...
    epochs: int
    gyro_count: int
    time_s: npt.NDArray[np.float64]
    q_RB_wxyz: npt.NDArray[np.float64]
    omega_BR_B_dps: npt.NDArray[np.float64]
    sigma_deg: npt.NDArray[np.float64]
    sigma_B_deg: npt.NDArray[np.float64]
    bias_dps: npt.NDArray[np.float64]
    protection_level_B_deg: npt.NDArray[np.float64]
    mode: npt.NDArray[np.uint8]
    gyros: npt.NDArray[np.uint32]
    fdi_available: npt.NDArray[np.uint8]
    events: list[dict[str, Any]]
    def __len__(self) -> int: ...
    @property
    def mode_names(self) -> npt.NDArray[np.object_]: ...
    def attitude_frame(self) -> pandas.DataFrame: ...
    def events_frame(self) -> pandas.DataFrame: ...

class Pipeline:
    calibration: Calibration
    def __init__(self, calibration: Union[Calibration, PathLike], config: _ConfigLike = ..., *,
                 units_dps: bool = ...) -> None: ...
    @property
    def gyro_count(self) -> int: ...
    @property
    def config(self) -> PipelineConfig: ...
    def step(self, time_s: float, raw: npt.ArrayLike, present: Optional[npt.ArrayLike] = ...,
             reference_wxyz: Optional[npt.ArrayLike] = ...) -> dict[str, Any]: ...
    def run(self, time_s: npt.ArrayLike, raw: npt.ArrayLike, present: Optional[npt.ArrayLike] = ...,
            reference_wxyz: Optional[npt.ArrayLike] = ...,
            reference_present: Optional[npt.ArrayLike] = ..., *, progress: _ProgressLike = ...) -> PipelineRun: ...
    def run_log(self, log: GyroLog, *, progress: _ProgressLike = ...) -> PipelineRun: ...
    def reset(self) -> None: ...
    def health(self) -> dict[str, Any]: ...
    def exclude(self, gyro: int, stamp_ns: int, force: bool = ...) -> dict[str, Any]: ...
    def reinstate(self, gyro: int, stamp_ns: int) -> dict[str, Any]: ...
    def reset_command(self, stamp_ns: int) -> dict[str, Any]: ...
    def describe_thresholds(self) -> str: ...

def score(attitude: Any, truth: Any, *, time_tolerance_s: float = ...,
          axis_B: Sequence[float] = ...) -> AttitudeScore: ...
def campaign_spec(spec: Union[PathLike, Mapping[str, Any], CampaignSpec], *,
                  base_dir: Optional[PathLike] = ...) -> CampaignSpec: ...

class CampaignResult:
    def __init__(self, csv: str, report: Union[str, Callable[[str], str]] = ...) -> None: ...
    csv: str
    @property
    def rows(self) -> pandas.DataFrame: ...
    @property
    def report(self) -> str: ...
    def __len__(self) -> int: ...

def campaign(spec: Union[PathLike, Mapping[str, Any], CampaignSpec], *, runs: Optional[Sequence[int]] = ...,
             base_dir: Optional[PathLike] = ..., jobs: int = ..., progress: _ProgressLike = ...) -> CampaignResult: ...

"""Extreme straight-line motion for redundant robot arms: plan, check and inspect.

Type stubs of the compiled module (PyO3). Arrays are numpy float64 arrays.
"""

import os
from pathlib import Path
from typing import Iterable, Literal, Optional, Sequence, Tuple, Union, type_check_only

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
Vector3 = Sequence[float]
# One angle (rad) per joint of the arm.
JointAngles = Sequence[float]
FloatArray = npt.NDArray[np.float64]

class Error(Exception):
    """Base class of every error the package raises."""

class InputError(Error):
    """Bad input: a robot file, model, configuration, task or option that cannot be used."""

class PlanningError(Error):
    """A valid task that cannot be planned (no seed could be prepared)."""

class CheckFailed(Error):
    """A trajectory file that does not hold up under the independent checker."""

class Robot:
    """An arm of six or seven revolute joints from a robot file: ``Robot("fr3")``,
    ``Robot("iiwa14")``, ``Robot("ur5e")`` or ``Robot(path)``."""

    def __init__(self, robot: PathLike = "fr3") -> None: ...
    @property
    def file(self) -> Path:
        """The robot file (a shipped robot's file, or the path as given)."""
    @property
    def name(self) -> str:
        """The robot's name in its file."""
    @property
    def joint_names(self) -> list[str]:
        """Names of the arm's n joints (6 or 7), base to tip (the order of every ``q``)."""
    @property
    def dof(self) -> int:
        """Number of joints n (6 or 7)."""
    @property
    def lower_limits(self) -> FloatArray:
        """Lower joint limits (rad), shape (n,)."""
    @property
    def upper_limits(self) -> FloatArray:
        """Upper joint limits (rad), shape (n,)."""
    @property
    def velocity_limits(self) -> FloatArray:
        """Joint velocity limits (rad/s), shape (n,)."""
    @property
    def home(self) -> Optional[FloatArray]:
        """A shipped arm's home (rad), shape (n,), where a job's program starts and ends unless
        given another; None for another robot file."""
    def fk(self, q: JointAngles) -> FloatArray:
        """The tool-centre-point pose at ``q`` as a 4x4 homogeneous transform (base frame)."""
    def jacobian(self, q: JointAngles) -> FloatArray:
        """The position Jacobian d(tcp)/dq at ``q``, shape (3, n)."""

class Task:
    """A task: move the tool from ``p0`` along ``d`` on the surface with normal ``n``."""

    @property
    def p0(self) -> FloatArray:
        """Start point (m), shape (3,)."""
    @property
    def d(self) -> FloatArray:
        """Unit direction, shape (3,)."""
    @property
    def n(self) -> FloatArray:
        """Unit surface normal, shape (3,)."""
    @property
    def path_length_m(self) -> Optional[float]:
        """The length of the task's path (m), or None for a line."""
    @property
    def q0_seed(self) -> Optional[FloatArray]:
        """The configuration the task was generated from (rad), shape (n,), or None."""

class Plan:
    """A planned task; arrays have one row per step, the seed first."""

    @property
    def q(self) -> FloatArray:
        """Joint configurations (rad), shape (T, n)."""
    @property
    def t(self) -> FloatArray:
        """Times since the start (s), shape (T,)."""
    @property
    def tcp(self) -> FloatArray:
        """Tool-centre-point positions (m, base frame), shape (T, 3)."""
    @property
    def tool_angle_deg(self) -> FloatArray:
        """Angle between the tool axis and the surface normal (degrees), shape (T,)."""
    @property
    def rho(self) -> FloatArray:
        """Joint-limit proximity per step, shape (T,)."""
    @property
    def controllers(self) -> list[Optional[str]]:
        """The controller acting from each step ("classical", "learned", "search"; None at the end)."""
    @property
    def path_length_m(self) -> float:
        """Path length (p_T - p0) . d (m)."""
    @property
    def termination(self) -> str:
        """Why the motion ended."""
    @property
    def seed(self) -> FloatArray:
        """The seed configuration (rad), shape (n,)."""
    @property
    def seed_source(self) -> str:
        """Where the seed came from (dp, generating, home, given, q_mu, q_jl)."""
    @property
    def reachable_m(self) -> Optional[float]:
        """The task's reachability bound (m) when reach=True was asked."""
    @property
    def below_bound(self) -> Optional[str]:
        """Why the plan ends below 0.9 x the bound, when reach=True was asked and it does
        (as `emg plan` prints it and the trajectory file records it)."""
    @property
    def task(self) -> Task:
        """The task."""
    def timed(
        self,
        limits: Optional[PathLike] = None,
        velocity_scaling: float = 1.0,
        acceleration_scaling: float = 1.0,
        tool_speed: Optional[float] = None,
        rate_hz: float = 1000.0,
    ) -> Motion:
        """The motion timed rest to rest within the joint limits (a MoveIt joint_limits.yaml,
        by default the one beside the robot file), sampled at ``rate_hz``."""
    def save(
        self,
        stem: PathLike,
        limits: Optional[PathLike] = None,
        velocity_scaling: float = 1.0,
        acceleration_scaling: float = 1.0,
        tool_speed: Optional[float] = None,
        rate_hz: float = 1000.0,
    ) -> list[Path]:
        """Writes STEM.json, STEM.csv and STEM.joint_trajectory.json (timed as ``timed`` says)
        as ``emg plan`` does."""

@type_check_only
class _JointSamples:
    """The joint samples of a timed motion (no class of the module: what ``Motion`` and
    ``JobPlan`` share); arrays have one row per sample."""

    @property
    def q(self) -> FloatArray:
        """Joint positions (rad), shape (N, n)."""
    @property
    def qd(self) -> FloatArray:
        """Joint velocities (rad/s), shape (N, n)."""
    @property
    def qdd(self) -> FloatArray:
        """Joint accelerations (rad/s²), shape (N, n)."""

class Motion(_JointSamples):
    """A plan timed rest to rest; arrays have one row per sample."""

    @property
    def t(self) -> FloatArray:
        """Sample times (s), shape (N,)."""
    @property
    def duration_s(self) -> float:
        """Time from rest to rest (s)."""
    @property
    def time_optimal_s(self) -> float:
        """TOPP-RA within the velocity, acceleration and tool-speed limits, no jerk limit (s)."""
    @property
    def tool_speed_share(self) -> float:
        """Share of the duration with the tool at >= 99 % of the requested speed."""
    @property
    def knots(self) -> FloatArray:
        """The path parameter (m of TCP travel) at each waypoint, shape (K,)."""
    @property
    def waypoints(self) -> FloatArray:
        """The waypoints of the path (rad), shape (K, n): a natural cubic spline between rests."""
    @property
    def rest_knots(self) -> npt.NDArray[np.uint64]:
        """Indices of the knots where the motion rests inside the path (unblended corners), shape (R,)."""
    @property
    def grid(self) -> FloatArray:
        """The TOPP-RA grid along the path, shape (M,)."""
    @property
    def limits(self) -> dict[str, FloatArray]:
        """The limits the samples hold: velocity, acceleration, jerk, shape (n,) each."""
    @property
    def tool_speed(self) -> float:
        """The largest tool speed asked for (m/s)."""

class JobPlan(_JointSamples):
    """A job's program (docs/jobs.md); arrays have one row per sample at 1 kHz."""

    @property
    def summary(self) -> dict:
        """The totals ``emg job`` prints (``drawn_m``, ``total_m``, ``duration_s``,
        ``ends_at_home``, ``least_pen_down_s``, ``least_pen_up_s``, ...)."""
    @property
    def strokes(self) -> list[dict]:
        """Every stroke's outcome in drawing order, as the program file's."""
    @property
    def segments(self) -> list[dict]:
        """The segments in time order: ``kind``, ``stroke`` and ``part`` for a stroke,
        ``start_s``, ``end_s``, and the samples as arrays ``time_s`` and ``q``."""
    @property
    def time_s(self) -> FloatArray:
        """Time of every sample (s), shape (N,)."""
    def write(self, path: PathLike) -> None:
        """Writes the program file ``emg check`` verifies."""

class JobPlacement:
    """Where to put a job's part (docs/placement.md)."""

    @property
    def certified(self) -> list[dict]:
        """The places planned as full jobs, best first; the first is the chosen place."""
    @property
    def screened(self) -> list[dict]:
        """Every screened place in grid order."""
    @property
    def base_pose(self) -> Optional[dict]:
        """Moving the base: its new pose (``translation_m``, ``rpy``); else None."""
    @property
    def transform(self) -> dict:
        """The chosen place as a job file's ``transform`` (``translation_m``, ``rpy``)."""
    @property
    def program(self) -> JobPlan:
        """The program planned at the chosen place."""
    def map_svg(self) -> str:
        """The heat map as SVG text (what ``emg place --map`` writes)."""

SeedArg = Union[Literal["dp", "generating", "home", "q_mu", "q_jl"], JointAngles, None]
ControllerArg = Literal["hybrid", "rl", "classical"]
PlannerArg = Optional[Literal["controller", "search"]]
TaskArg = Union[Task, Tuple[Vector3, Vector3, Vector3]]

class Planner:
    """Plans extreme straight-line motions for one robot with its models and configuration."""

    def __init__(
        self,
        robot: PathLike = "fr3",
        models: Optional[PathLike] = None,
        config: Union[PathLike, dict, None] = None,
        surface: Optional[str] = None,
        tolerance_mm: Optional[float] = None,
        cone_deg: Optional[float] = None,
    ) -> None: ...
    @property
    def robot(self) -> Robot:
        """The robot."""
    @property
    def models(self) -> dict[str, bool]:
        """Whether the diffusion seeder and the policy are loaded."""
    def plan(
        self,
        p0: Vector3,
        d: Vector3,
        n: Vector3,
        seed: SeedArg = None,
        controller: Optional[ControllerArg] = None,
        planner: PlannerArg = None,
        reach: bool = True,
    ) -> Plan:
        """Plans the task (p0, d, n); the GIL is released while planning."""
    def plan_path(
        self,
        path: Union[str, os.PathLike[str], dict],
        seed: SeedArg = None,
        controller: Optional[ControllerArg] = None,
        planner: PlannerArg = None,
        reach: bool = True,
    ) -> Plan:
        """Plans a path task (a path file or a dict in its layout, docs/paths.md) as far along the path as it goes."""
    def plan_many(
        self,
        tasks: Iterable[TaskArg],
        seed: SeedArg = None,
        controller: Optional[ControllerArg] = None,
        planner: PlannerArg = None,
        reach: bool = True,
    ) -> list[Plan]:
        """Plans every task in parallel with the GIL released; plans come in task order."""
    def plan_job(
        self,
        job: Union[PathLike, dict],
        placement: Optional[dict] = None,
        tolerance_mm: float = 0.5,
        home: Optional[JointAngles] = None,
        corner_tolerance_mm: Optional[float] = None,
    ) -> JobPlan:
        """Plans a job (a job file, an SVG drawing placed by ``placement``, or a dict in the job
        file's layout) as ``emg job`` does; the program starts and ends at ``home``, by default
        the job's, else the shipped arm's (``Robot.home``); an SVG drawing's corners are rounded
        within ``corner_tolerance_mm`` of ``tolerance_mm`` (by default none)."""
    def place_job(
        self,
        job: Union[PathLike, dict],
        region: dict,
        placement: Optional[dict] = None,
        tolerance_mm: float = 0.5,
        positions: int = 10,
        rotations: int = 5,
        certify: int = 5,
        score: Literal["bound", "point_ik"] = "bound",
        home: Optional[JointAngles] = None,
        corner_tolerance_mm: Optional[float] = None,
    ) -> JobPlacement:
        """Finds where to put a job's part as ``emg place`` does; ``home`` as for ``plan_job``."""
    def reach(self, p0: Vector3, d: Vector3, n: Vector3) -> float:
        """The task's reachability bound (m)."""

class CheckReport:
    """What the independent checker measured on a trajectory file that holds up."""

    layout: str
    robot: Path
    points: int
    duration_s: float
    path_length_m: float
    max_line_deviation_m: float
    max_tool_angle_deg: float
    min_clearance_m: float
    min_clearance_links: Tuple[str, str]
    peak_speed_fraction: list[float]
    peak_acceleration_rad_s2: list[float]
    recorded_end_verified: bool

def load_tasks(path: PathLike, robot: PathLike = "fr3") -> list[Task]:
    """The tasks of a task file (JSON or EMGTASKS), validated for ``robot``."""

class JobCheckReport:
    """What the independent checker verified on a job's program that holds up."""

    layout: str
    robot: Path
    stroke_parts: int
    moves: int
    points: int

def check(
    path: PathLike, robot: Optional[PathLike] = None
) -> Union[CheckReport, JobCheckReport]:
    """Verifies a trajectory file or a job's program with the independent checker, as
    ``emg check`` does; raises CheckFailed."""

class ExportReport:
    """What an export wrote (``export``)."""

    format: str
    files: list[Path]
    summary: str
    points_before: Optional[int]
    points_after: Optional[int]
    tolerance_rad: Optional[float]
    max_joint_deviation_rad: Optional[float]
    max_tool_deviation_m: Optional[float]
    servoj_targets: int

def export(
    path: PathLike,
    format: Literal["ros2-mcap", "urscript", "rapid", "krl"],
    out: PathLike,
    robot: Optional[PathLike] = None,
    tolerance_rad: Optional[float] = None,
    max_servoj_lines: Optional[int] = None,
    urscript: Optional[Literal["native", "servoj"]] = None,
) -> ExportReport:
    """Exports a joint trajectory file or a job's program as ``emg export`` does:
    ``"ros2-mcap"`` (a ROS 2 trajectory_msgs/msg/JointTrajectory in an MCAP file, its points
    thinned within ``tolerance_rad``, default 1e-5; a job's tool switching beside it on
    ``/emg/tool_output``, std_msgs/msg/Bool) or ``"urscript"``: ``urscript="native"`` (one
    program of movej, movel and blended movep through the plan's poses, the tool switched by its
    output; a job's program on the shipped UR5e, its default there) or ``"servoj"`` (a servoj
    target every 2 ms, at most ``max_servoj_lines`` per program, default 2500), or ``"rapid"``
    (a job's program on a six-joint ABB arm, the shipped ``irb120``: one RAPID module of MoveAbsJ
    and MoveL with zones, configuration data and the tool's SetDO), or ``"krl"`` (a job's
    program on a six-joint KUKA arm with ROS-Industrial's ``tool0``, the shipped ``kr16``: a KRL
    program, ``out`` its ``.src`` named as KRL names programs, its points in the ``.dat`` beside
    it: PTP and LIN with C_DIS, Status and Turn, the tool's $OUT). Raises InputError for a wrong
    input, writing nothing."""

"""The measuring frame (a tracker's) and the world frame: kept, registered by a best fit, or a given transform.

A best fit is a least-squares rigid fit (rotation and translation, no scale) of the poses' measured barycentres to
their commanded positions, by ``scipy.spatial.transform.Rotation.align_vectors`` on the centred point sets (the Kabsch
solution). It needs commanded positions at three or more poses that are not collinear.

A best fit absorbs accuracy: its rigid motion has 6 degrees of freedom, taken from the 3n coordinates of n poses, so
the residual keeps only 3n - 6 of them and the AP_p figures it leaves understate the robot's error (for independent
errors of one size, by the fraction 6 / 3n of their variance). ``registration="auto"`` (the default) registers only
where that is harmless (:func:`harmless`): at least :data:`AUTO_MIN_POSES` poses, the fewest whose fit uses less than
half their coordinates (6 of 15); no pose whose own three coordinates the fit uses more than half of (its leverage:
the trace of its block of the hat matrix of a rigid motion at the commanded positions, over 3); and a rotation
determined to :data:`AUTO_MAX_ROTATION_ERROR_RAD` about its least determined axis (the poses spread off their main
line relative to the residual). Otherwise it keeps the measuring frame.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np

from tribokin.checks import number_list, toml_mapping
from tribokin.confinement import regular_file
from tribokin.errors import InputError, SettingsError, closest_hint
from tribokin.iso9283.metrics import barycenter
from tribokin.measurement.contract import Measurements
from tribokin.units import MDEG_PER_RAD, UM_PER_M

#: Poses are collinear when the second singular value of their centred commanded positions is below
#: this fraction of the first.
COLLINEAR_RATIO = 1e-6
#: Degrees of freedom of a rigid motion: the coordinates a best fit absorbs.
RIGID_DOF = 6
#: ``auto`` registers on at least this many poses: 6 < 3n / 2, the fit using less than half the coordinates.
AUTO_MIN_POSES = 5
#: ``auto``: the largest share of one pose's coordinates the fit may use (its leverage / 3).
AUTO_MAX_SHARE = 0.5
#: ``auto``: the largest standard error of the fitted rotation about its least determined axis [rad] (turns a
#: cloud's shape by at most 1 % of its size).
AUTO_MAX_ROTATION_ERROR_RAD = 1e-2
#: A given rotation matrix's rows are orthonormal to this (largest |RᵀR - I|).
ROTATION_TOLERANCE = 1e-6
#: The choices of ``registration=`` (and ``--registration``) besides a :class:`Transform`.
CHOICES = ("auto", "none", "best-fit")
Choice = Literal["auto", "none", "best-fit"]
#: The keys of a transform file.
TRANSFORM_KEYS = ("rotation", "rpy_deg", "translation_m")

UNAVAILABLE = "the measuring frame is not registered: that needs commanded positions at three or more poses " \
              "that are not on one line"
NO_COMMANDED = "the measuring frame is not registered: the file has no commanded positions (cx, cy, cz)"


class RegistrationWarning(UserWarning):
    """A best fit on poses too few or too ill-spread for it to be harmless: it absorbs part of the accuracy error."""


@dataclass(frozen=True)
class Transform:
    """A given rigid motion of the measuring frame into the world frame: ``p_world = rotation @ p + translation_m``.

    Attributes:
        rotation: (3, 3) rotation matrix (rows orthonormal to :data:`ROTATION_TOLERANCE`, determinant +1).
        translation_m: (3,) [m].
        source: where it was given (a file's name), for the output.
    """

    rotation: np.ndarray
    translation_m: np.ndarray
    source: str = "given"

    def checked(self, source=None) -> Transform:
        """The transform as arrays, checked: an :class:`InputError` naming the file ``source`` and its key, or without
        one a :class:`SettingsError` naming the argument ``registration``."""
        def refuse(message: str, key: str):
            if source is None:
                raise SettingsError(message, "registration")
            raise InputError(message, source, key)

        rotation = np.asarray(self.rotation, dtype=float) if _numbers(self.rotation, (3, 3)) else None
        if rotation is None:
            refuse("the rotation must be 3 rows of 3 finite numbers", "rotation")
        error = float(np.abs(rotation.T @ rotation - np.eye(3)).max())
        if error > ROTATION_TOLERANCE or np.linalg.det(rotation) <= 0:
            refuse(f"not a rotation: its rows must be orthonormal to {ROTATION_TOLERANCE:g} (RᵀR differs from the "
                   f"identity by {error:.3g}) and its determinant +1 (it is {np.linalg.det(rotation):.6g}); give the "
                   "rotation of the measuring frame into the world frame, or rpy_deg", "rotation")
        if not _numbers(self.translation_m, (3,)):
            refuse("the translation must be 3 finite numbers [m]", "translation_m")
        return Transform(rotation, np.asarray(self.translation_m, dtype=float), str(self.source))


def _numbers(value, shape: tuple[int, ...]) -> bool:
    """Whether ``value`` is an array of finite numbers of ``shape`` (no booleans, no text)."""
    try:
        array = np.asarray(value)
    except (ValueError, TypeError):
        return False
    return array.shape == shape and array.dtype.kind in "iuf" and bool(np.isfinite(array).all())


def read_transform(path, option: str = "--transform") -> Transform:
    """The transform in the TOML file ``path``: ``translation_m = [x, y, z]`` and either ``rotation`` (3 rows) or
    ``rpy_deg = [roll, pitch, yaw]`` (fixed axes x-y-z, as ``robot.base_rpy_deg``); errors name the file and key."""
    real = regular_file(path, "command line", option)
    try:
        text = real.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError("not valid TOML: not UTF-8 text", path) from None
    mapping = toml_mapping(text, path)
    for key in mapping:
        if key not in TRANSFORM_KEYS:
            raise InputError(f"unknown key; a transform has {', '.join(TRANSFORM_KEYS)}"
                             f"{closest_hint(key, TRANSFORM_KEYS)}", path, key)
    if ("rotation" in mapping) == ("rpy_deg" in mapping):
        raise InputError("give the rotation as either rotation (3 rows of 3) or rpy_deg (roll, pitch, yaw), one of "
                         "them", path, "rotation")
    if "translation_m" not in mapping:
        raise InputError("missing: the translation [m] of p_world = rotation · p_measured + translation_m", path,
                         "translation_m")
    rotation = mapping.get("rotation")
    if "rpy_deg" in mapping:
        from scipy.spatial.transform import Rotation

        rpy = number_list(mapping["rpy_deg"], path, "rpy_deg")
        if len(rpy) != 3:
            raise InputError(f"needs 3 values, roll, pitch, yaw [deg] (got {len(rpy)})", path, "rpy_deg")
        rotation = Rotation.from_euler("xyz", rpy, degrees=True).as_matrix()
    return Transform(rotation, mapping["translation_m"], str(path)).checked(path)


@dataclass(frozen=True)
class Registration:
    """``p_base = rotation @ p_measuring + translation_m``.

    Attributes:
        rotation: (3, 3) rotation of the measuring frame into the world frame.
        translation_m: (3,) [m].
        rms_residual_m: root mean square of |registered barycentre - commanded| over the poses [m] (``None``: a given
            transform, the file without commanded positions).
        poses: names of the poses fitted (or compared, for a given transform).
        method: ``"best-fit"`` or ``"given"``.
        shares: per pose, the share of its three coordinates the best fit used (its leverage / 3; empty when given).
        rotation_error_rad: standard error of the fitted rotation about its least determined axis, from the residual
            [rad] (``None`` when given).
    """

    rotation: np.ndarray
    translation_m: np.ndarray
    rms_residual_m: float | None
    poses: tuple[str, ...]
    method: str = "best-fit"
    shares: tuple[float, ...] = ()
    rotation_error_rad: float | None = None

    def to_base(self, points_m: np.ndarray) -> np.ndarray:
        """(..., 3) points of the measuring frame in the world frame [m]."""
        return points_m @ self.rotation.T + self.translation_m

    @property
    def angle_rad(self) -> float:
        """The rotation's angle [rad]."""
        return float(np.arccos(np.clip((np.trace(self.rotation) - 1) / 2, -1.0, 1.0)))

    @property
    def coordinates_used(self) -> int:
        """Of the 3n coordinates of the poses, those the fit used (:data:`RIGID_DOF`; 0 for a given transform)."""
        return RIGID_DOF if self.method == "best-fit" else 0


def _rms(residual: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(residual ** 2, axis=1))))


def shares(commanded_m: np.ndarray) -> np.ndarray:
    """Per point, the share of its three coordinates a rigid fit at the (k, 3) points uses: the trace of its 3 x 3
    block of the hat matrix of the linearised rigid motion (translation t, small rotation w: t + w x d), over 3.
    They sum to 6 / 3 = 2 over the points."""
    d = commanded_m - commanded_m.mean(axis=0)
    zero = np.zeros(len(d))
    cross = np.stack([np.stack([zero, -d[:, 2], d[:, 1]], -1), np.stack([d[:, 2], zero, -d[:, 0]], -1),
                      np.stack([-d[:, 1], d[:, 0], zero], -1)], axis=1)  # [d]x, (k, 3, 3)
    design = np.concatenate([np.broadcast_to(np.eye(3), cross.shape), -cross], axis=2).reshape(-1, 6)
    hat = design @ np.linalg.pinv(design)
    return np.diag(hat).reshape(-1, 3).sum(axis=1) / 3


def register(measured_m: np.ndarray, commanded_m: np.ndarray, poses: tuple[str, ...] = ()) -> Registration | None:
    """Rigid least-squares fit of (k, 3) measured points to (k, 3) commanded points [m].

    None when fewer than three points are given or they are collinear (the rotation about their line
    is then undetermined).
    """
    if len(commanded_m) < 3:
        return None
    measured_centre, commanded_centre = measured_m.mean(axis=0), commanded_m.mean(axis=0)
    singular = np.linalg.svd(commanded_m - commanded_centre, compute_uv=False)
    if singular[1] <= COLLINEAR_RATIO * singular[0]:
        return None
    from scipy.spatial.transform import Rotation  # here: scipy.spatial's import is not free (benchmarks/startup.py)

    rotation = Rotation.align_vectors(commanded_m - commanded_centre, measured_m - measured_centre)[0].as_matrix()
    translation = commanded_centre - rotation @ measured_centre
    rms = _rms(measured_m @ rotation.T + translation - commanded_m)
    k = len(commanded_m)
    scatter = rms * np.sqrt(k / (3 * k - RIGID_DOF))  # per coordinate, the residual keeping 3k - 6 of them
    rotation_error = float(scatter / np.hypot(singular[1], singular[2]))
    return Registration(rotation, translation, rms, tuple(poses), "best-fit",
                        tuple(float(s) for s in shares(commanded_m)), rotation_error)


def _barycentres(measurements: Measurements) -> tuple[np.ndarray, np.ndarray | None]:
    """Each pose's barycentre (all its rows) and mean commanded position (``None``: the file has none)."""
    measured = np.array([barycenter(p.pooled("positions_m")) for p in measurements.poses])
    if measurements.poses[0].pooled("commanded_m") is None:
        return measured, None
    return measured, np.array([p.pooled("commanded_m").mean(axis=0) for p in measurements.poses])


def register_measurements(measurements: Measurements) -> Registration | None:
    """Register the frame on each pose's barycentre (all its rows) and mean commanded position.

    None without commanded positions or with fewer than three non-collinear poses (:data:`UNAVAILABLE`).
    """
    measured, commanded = _barycentres(measurements)
    if commanded is None:
        return None
    return register(measured, commanded, tuple(p.name for p in measurements.poses))


def harmless(registration: Registration) -> str | None:
    """Why a best fit is not harmless (module docstring), or ``None`` when it is."""
    n = len(registration.poses)
    if n < AUTO_MIN_POSES:
        return (f"a best fit on {n} poses uses {RIGID_DOF} of their {3 * n} coordinates and absorbs as large a share "
                f"of the robot's accuracy error (AP_p then understates it); at least {AUTO_MIN_POSES} poses make the "
                "share less than half")
    share, pose = max(zip(registration.shares, registration.poses, strict=True))
    if share > AUTO_MAX_SHARE:
        return (f"a best fit uses {share:.0%} of pose {pose}'s coordinates, absorbing as much of its accuracy error: "
                "the poses are spread unevenly (at most half makes it harmless)")
    if registration.rotation_error_rad > AUTO_MAX_ROTATION_ERROR_RAD:
        return (f"the poses lie so close to one line, for their residual, that a best fit's rotation is uncertain by "
                f"{registration.rotation_error_rad * MDEG_PER_RAD:.3g} mdeg (more than "
                f"{AUTO_MAX_ROTATION_ERROR_RAD * MDEG_PER_RAD:.3g})")
    return None


@dataclass(frozen=True)
class Frame:
    """The measuring frame as the choice left it.

    Attributes:
        choice: ``"auto"``, ``"none"``, ``"best-fit"`` or ``"given"`` (a :class:`Transform`).
        registration: the registration made, or ``None`` (the measuring frame kept).
        why: why it was made or not, one sentence.
        warning: a best fit that is not harmless, what it absorbed (``None``: none).
    """

    choice: str
    registration: Registration | None
    why: str
    warning: str | None = None

    def summary(self) -> dict:
        """``summary.json``'s and ``calibration.json``'s registration entry (lengths in µm, angles in mdeg)."""
        registration = self.registration
        entry = {"choice": self.choice, "made": registration is not None, "why": self.why, "warning": self.warning}
        if registration is None:
            return entry
        rms = registration.rms_residual_m
        return {**entry, "method": registration.method, "rms_residual_um": None if rms is None else rms * UM_PER_M,
                "rotation": registration.rotation.tolist(), "translation_m": registration.translation_m.tolist(),
                "rotation_angle_mdeg": registration.angle_rad * MDEG_PER_RAD,
                "translation_um": float(np.linalg.norm(registration.translation_m)) * UM_PER_M,
                "poses": list(registration.poses),
                "coordinates_used": [registration.coordinates_used, 3 * len(registration.poses)],
                "largest_share": max(registration.shares) if registration.shares else None,
                "rotation_error_mdeg": None if registration.rotation_error_rad is None else
                registration.rotation_error_rad * MDEG_PER_RAD}

    def describe(self) -> str:
        """One line for the console: what was absorbed, or why the frame is kept."""
        registration = self.registration
        if registration is None:
            return self.why
        n = len(registration.poses)
        head = (f"best fit on {n} poses ({registration.coordinates_used} of their {3 * n} coordinates)"
                if registration.method == "best-fit" else self.why)
        rms = "" if registration.rms_residual_m is None else \
            f", rms residual {registration.rms_residual_m * UM_PER_M:.3f} µm"
        return (f"{head}{rms}; rigid motion: rotation {registration.angle_rad * MDEG_PER_RAD:.6g} mdeg, translation "
                f"{float(np.linalg.norm(registration.translation_m)) * UM_PER_M:.6g} µm")


def checked_choice(registration) -> Choice | Transform:
    """``registration=`` checked: one of :data:`CHOICES` or a checked :class:`Transform` (a
    :class:`~tribokin.errors.SettingsError` naming ``registration``)."""
    if isinstance(registration, Transform):
        return registration.checked()
    if not isinstance(registration, str) or registration not in CHOICES:
        raise SettingsError(f"must be one of {', '.join(CHOICES)} or a Transform (got {registration!r})"
                            f"{closest_hint(str(registration), CHOICES)}", "registration")
    return registration


def choose_frame(measurements: Measurements, registration: Choice | Transform = "auto") -> Frame:
    """The measuring frame of ``measurements`` as ``registration`` (checked by :func:`checked_choice`) leaves it:
    ``"none"`` keeps it, ``"best-fit"`` registers it (an :class:`InputError` naming the file where that is impossible;
    a :class:`RegistrationWarning` where it is not harmless), ``"auto"`` registers it only where harmless, a
    :class:`Transform` is applied as given."""
    if isinstance(registration, Transform):
        measured, commanded = _barycentres(measurements)
        rms = None if commanded is None else \
            _rms(measured @ registration.rotation.T + registration.translation_m - commanded)
        return Frame("given", Registration(registration.rotation, registration.translation_m, rms,
                                           tuple(p.name for p in measurements.poses), "given"),
                     f"the transform given in {registration.source}")
    if registration == "none":
        return Frame("none", None, "the measuring frame is kept as measured (registration 'none')")
    fitted = register_measurements(measurements)
    if fitted is None:
        why = NO_COMMANDED if measurements.poses[0].pooled("commanded_m") is None else UNAVAILABLE
        if registration == "best-fit":
            raise InputError(f"registration 'best-fit' needs commanded positions (cx, cy, cz) at three or more poses "
                             f"not on one line ({why.split(': ', 1)[1]}); add them, or keep the measuring frame",
                             measurements.source, "cx_m")
        return Frame("auto", None, why)
    concern = harmless(fitted)
    if registration == "auto":
        if concern is not None:
            return Frame("auto", None, f"the measuring frame is kept as measured: {concern}")
        return Frame("auto", fitted, f"registered by a best fit: {len(fitted.poses)} well-spread poses")
    warning = None
    if concern is not None:
        warning = f"registration by best fit: {concern}"
        warnings.warn(warning, RegistrationWarning, stacklevel=3)
    return Frame("best-fit", fitted, "registered by a best fit, as asked", warning)

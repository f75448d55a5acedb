"""TurtleBot3 Burger constants, read from ``models/turtlebot3_burger.yaml``."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import yaml

from f2n_drake.models import model_path


@dataclass(frozen=True)
class RobotParams:
    """Robot body, velocity limits and LiDAR (SI units: m, m/s, rad/s, Hz)."""

    radius_m: float
    height_m: float
    v_max_mps: float
    omega_max_radps: float
    lidar_min_range_m: float
    lidar_max_range_m: float
    lidar_num_beams: int
    lidar_rate_hz: float


@lru_cache(maxsize=1)
def turtlebot3_burger() -> RobotParams:
    """The TurtleBot3 Burger (radius 0.105 m, 0.22 m/s, 2.84 rad/s, LDS-01 0.12-3.5 m)."""
    data = yaml.safe_load(model_path("turtlebot3_burger.yaml").read_text())
    body, limits, lidar = data["body"], data["limits"], data["lidar"]
    return RobotParams(
        radius_m=float(body["radius_m"]),
        height_m=float(body["height_m"]),
        v_max_mps=float(limits["max_linear_velocity_mps"]),
        omega_max_radps=float(limits["max_angular_velocity_radps"]),
        lidar_min_range_m=float(lidar["min_range_m"]),
        lidar_max_range_m=float(lidar["max_range_m"]),
        lidar_num_beams=int(lidar["num_beams"]),
        lidar_rate_hz=float(lidar["rate_hz"]),
    )

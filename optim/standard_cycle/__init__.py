"""The standard pick cycle (25 mm up, 305 mm across, 25 mm down and back), time-optimal, for any arm.

- :mod:`.path`: the gate (:class:`StandardCycle`, rounded corners) and its points;
- :mod:`.timing`: rows of speed, acceleration and torque limits along a joint path, and the
  project's TOPP-RA on them (:func:`time_rows`, :class:`GateTiming`);
- :mod:`.delta_cycle`: a delta robot (closed form + closed-chain torques), its fourth axis' turn beside the move;
- :mod:`.serial_cycle`: a serial arm (its IK and RNEA).
"""

from pinarms.optim.standard_cycle.delta_cycle import (TOOL_ACCELERATION_FACTOR, DeltaCycleTime, delta_cycle_time,
                                                      delta_gate_rows, delta_path_rows, delta_standard_cycle,
                                                      tool_turn_limits, tool_turn_time, turn_angle)
from pinarms.optim.standard_cycle.path import StandardCycle, gate_breaks, gate_length, gate_points
from pinarms.optim.standard_cycle.serial_cycle import serial_gate_rows, serial_standard_cycle
from pinarms.optim.standard_cycle.timing import GateTiming, JointPathRows, limit_usage, profile_position, time_rows

__all__ = ["StandardCycle", "gate_length", "gate_points", "gate_breaks", "GateTiming", "JointPathRows",
           "time_rows", "limit_usage", "delta_gate_rows", "delta_path_rows", "delta_standard_cycle",
           "serial_gate_rows", "serial_standard_cycle", "delta_cycle_time", "DeltaCycleTime", "tool_turn_time",
           "turn_angle", "tool_turn_limits", "TOOL_ACCELERATION_FACTOR", "profile_position"]

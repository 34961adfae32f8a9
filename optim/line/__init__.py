"""The line: items on a moving belt, several arms picking on the fly, assignment, simulation, sizing.

``schedule`` keeps the time offsets of several arms cycling together (:func:`schedule_line`).
"""

from pinarms.optim.line.schedule import LineSchedule, schedule_line

__all__ = ["LineSchedule", "schedule_line"]

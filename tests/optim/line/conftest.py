import pytest

from pinarms import robots
from pinarms.optim.line.belt import Belt, PlaceBox
from pinarms.optim.line.station import Station, base_pose


@pytest.fixture(scope="module")
def scara_line():
    """Seed 000's SCARA beside a 0.3 m belt (surface 0.80 m), its box beside it."""
    belt = Belt(origin=(0.0, 0.0, 0.80), speed=0.2, width=0.3, length=3.0)
    station = Station("scara 1", robots.load("scara_mushroom"), base_pose(1.0, 0.30, 0.78),
                      PlaceBox((0.8, 0.45, 0.93)))
    return belt, station

"""The ``scheduler`` argument of the execution layer: checked, and named in words."""

from __future__ import annotations

import pytest

from pinarms import execution
from pinarms.errors import InvalidInput
from pinarms.schedulers import describe_scheduler, parse_scheduler


def test_scheduler_strings():
    assert describe_scheduler(None) == "serial (this process)"
    assert describe_scheduler("processes:3") == "local Dask cluster, 3 worker processes"
    assert describe_scheduler("processes:1") == "local Dask cluster, 1 worker process"
    assert describe_scheduler("tcp://10.0.0.5:8786") == "Dask cluster at tcp://10.0.0.5:8786"
    assert parse_scheduler("serial") == ("serial", None)
    assert parse_scheduler(" processes:2 ") == ("processes", 2)
    with pytest.raises(InvalidInput, match="unknown scheduler"):
        parse_scheduler("threads")
    with pytest.raises(InvalidInput, match="positive integer"):
        parse_scheduler("processes:0")
    with pytest.raises(InvalidInput, match="PORT from 1 to 65535"):
        parse_scheduler("tcp://host:70000")
    with pytest.raises(InvalidInput, match="got int"):
        parse_scheduler(3)


def test_env_scheduler_reads_the_standard_variable(monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    with pytest.raises(InvalidInput, match="DASK_SCHEDULER_ADDRESS"):
        describe_scheduler("env")
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "tcp://192.0.2.1:8786")
    assert describe_scheduler("env") == "Dask cluster at tcp://192.0.2.1:8786"
    assert parse_scheduler("env") == ("address", "tcp://192.0.2.1:8786")


def test_the_execution_layer_names_the_same_function():
    assert execution.describe_scheduler is describe_scheduler

"""An FMU instance through fmpy's FMU2Slave with a logger that keeps every message."""

import shutil
from ctypes import byref
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy

HOVER = (1.0 * 9.81 / (4 * 10.0)) ** 0.5
"""Motor state at which the default quadrotor (1 kg, k = 10 N) hovers: sqrt(mg / 4k)."""

ROTORS = {"Quadrotor": 4, "Hexacopter": 6}
"""The multirotor FMUs (one model, two rotor tables) and their rotor counts."""


def hover(model: str) -> float:
    """Motor state at which the default vehicle of `model` hovers: sqrt(mg / nk)."""
    return (1.0 * 9.81 / (ROTORS[model] * 10.0)) ** 0.5


def motors(model: str) -> list[str]:
    """The motor command inputs of a multirotor FMU, in motor order."""
    return [f"motor_command_{i}" for i in range(ROTORS[model])]


class LoggedSlave:
    """A Co-Simulation instance whose log messages land in `messages`."""

    def __init__(self, fmu: Path, name: str = "instance", logging_on: bool = True):
        self.model_description = read_model_description(str(fmu))
        self.directory = extract(str(fmu))
        self.messages: list[tuple[int, str, str]] = []
        # The callback objects must outlive the instance: keep them on self.
        self._logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._logger
        addLoggerProxy(byref(self.callbacks))
        self.slave = FMU2Slave(
            guid=self.model_description.guid,
            unzipDirectory=self.directory,
            modelIdentifier=self.model_description.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.slave.instantiate(callbacks=self.callbacks, loggingOn=logging_on)
        self.vrs = {v.name: v.valueReference for v in self.model_description.modelVariables}

    def _log(self, _env, _instance, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def start(self, start_time: float = 0.0, stop_time: float | None = None) -> None:
        self.slave.setupExperiment(startTime=start_time, stopTime=stop_time)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()

    def real(self, *names: str) -> list[float]:
        return self.slave.getReal([self.vrs[n] for n in names])

    def outputs(self) -> list[float]:
        names = [
            v.name
            for v in self.model_description.modelVariables
            if v.causality == "output" and v.type == "Real"
        ]
        return self.real(*names)

    def last_message(self) -> str:
        return self.messages[-1][2]

    def close(self) -> None:
        self.slave.freeInstance()
        shutil.rmtree(self.directory, ignore_errors=True)

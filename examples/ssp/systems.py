"""The closed loops examples/ssp builds: each system is a list of FMUs (instance name, FMU file
name in the FMU folder, parameter values) wired by name, and the plant outputs to watch.

Wiring is by name: every input of one FMU connects to the output of the same name of another
FMU in the system (build.py refuses an input two FMUs could feed). A new FMU (a Policy.fmu from
`flyloop-fmu-pack policy`) joins as one more `Component`, a new system as one more entry of
SYSTEMS: its inputs named like Quadrotor.fmu's outputs and its outputs like Quadrotor.fmu's
or RateController.fmu's inputs connect themselves.
"""

from dataclasses import dataclass, field

HOVER = (9.81 / 40) ** 0.5  # motor state / normalised thrust that carries the 1 kg default quad X
START_Z = 1.0  # m: both systems start at rest at this height


@dataclass(frozen=True)
class Component:
    name: str  # instance name in the SSP
    fmu: str  # file name in the FMU folder (dist/fmu)
    parameters: dict[str, float] = field(default_factory=dict)  # parameters and input start values
    # Inputs that may stay unconnected and keep their start values; any other input no output
    # feeds and no parameter binds is refused (a misnamed variable would otherwise sit at 0).
    open_inputs: tuple[str, ...] = ()


@dataclass(frozen=True)
class System:
    name: str
    description: str
    components: tuple[Component, ...]
    stop_time: float  # s, the SSP's DefaultExperiment
    step_size: float  # s, the communication step the engines run (RateController's 4 ms grid)
    watch: tuple[str, ...] = ("plant.x", "plant.y", "plant.z", "plant.yaw")  # recorded outputs


PLANT = Component(
    "plant",
    "Quadrotor.fmu",
    {"seed": 1, "initial_z": START_Z, "initial_motor": HOVER, "wind_enabled": 0},
    # No external wind; healthy motors (the effectiveness inputs keep their start value 1).
    open_inputs=(
        "wind_input_x",
        "wind_input_y",
        "wind_input_z",
        *(f"motor_effectiveness_{i}" for i in range(4)),
    ),
)
RATES = Component("rates", "RateController.fmu")

SYSTEMS = {
    # (a) Quadrotor + RateController + AttitudeController: level hover at 1 m, then a yaw step
    # to 0.5 rad at 2 s (a yaw step moves no position: the vehicle must stay where it is).
    "attitude_hover": System(
        "attitude_hover",
        "Quadrotor.fmu flown through PX4's rate loop (RateController.fmu) by a PD attitude "
        "controller (AttitudeController.fmu): hover at 1 m, yaw step to 0.5 rad at 2 s",
        (
            PLANT,
            RATES,
            Component(
                "attitude",
                "AttitudeController.fmu",
                {"target_z": START_Z, "target_yaw": 0.5, "step_time": 2.0, "hover_thrust": HOVER},
            ),
        ),
        stop_time=6.0,
        step_size=0.004,
    ),
    # (b) Quadrotor + RateController with a constant setpoint: hover thrust, zero rates, bound
    # as start values of RateController's inputs (nothing feeds them). Open loop in height:
    # the vehicle holds its attitude; its height drifts only by the start transient.
    "rates_hover": System(
        "rates_hover",
        "Quadrotor.fmu held level by PX4's rate loop (RateController.fmu) on a constant "
        "setpoint: hover thrust, zero body rates",
        (
            PLANT,
            Component(
                "rates",
                "RateController.fmu",
                {"thrust": HOVER, "roll_rate": 0.0, "pitch_rate": 0.0, "yaw_rate": 0.0},
            ),
        ),
        stop_time=3.0,
        step_size=0.004,
    ),
}

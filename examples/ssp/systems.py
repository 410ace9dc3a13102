"""The closed loops examples/ssp builds: each system is a list of FMUs (instance name, FMU file
name in the FMU folder, parameter values) wired by name, and the plant outputs to watch.

Wiring is by name: every input of one FMU connects to the output of the same name of another
FMU in the system (build.py refuses an input two FMUs could feed). A new FMU (a Policy.fmu from
`flyloop-fmu-pack policy`) joins as one more `Component`, a new system as one more entry of
SYSTEMS: its inputs named like Quadrotor.fmu's outputs and its outputs like Quadrotor.fmu's
or RateController.fmu's inputs connect themselves.
"""

from dataclasses import dataclass, field
from pathlib import Path

import tomllib

HOVER = (9.81 / 40) ** 0.5  # motor state / normalised thrust that carries the 1 kg default quad X
START_Z = 1.0  # m: the controller systems start at rest at this height
# Every component's bindings share this name (build.py writes it): ecos applies the named set
# at init (its convention's name), fmpy gets them merged (engines.py).
PARAMETER_SET = "initialValues"

# The policy systems fly a gym episode: the start and target QuadHover-v0 draws for the seed
# (level start, no wind; tests/fmu/test_fmu_ssp.py checks the gym draws these), so the FMU
# system and the gym episode can be compared step by step.
HEXA_HOVER = (9.81 / 60) ** 0.5  # the 1 kg default hexa X: six rotors of k = 10 N
HEXA_SEED = 2_000_003  # policies/hexa_hover's episode (tests/fmu/test_fmu_policy.py's too)
HEXA_TARGET = (-0.7264971733093262, 1.1584380865097046, 1.9632468223571777)  # m, world ENU
OFFBOARD_SEED = 1  # policies/px4_offboard_hover's episode on the nominal Iris
OFFBOARD_TARGET = (-0.3244643807411194, 0.7180993556976318, 0.4697224199771881)
POLICY_START_Z = 1.5  # m: QuadHover's start height
# The Iris the offboard policy was trained on (flyloop-sitl --px4's vehicle), its wind off.
IRIS = {
    k: v
    for k, v in tomllib.loads(
        (Path(__file__).resolve().parents[2] / "sitl" / "presets" / "px4_iris.toml").read_text()
    ).items()
    if k != "wind_enabled"
}
IRIS_HOVER = (IRIS["mass"] * 9.81 / (4 * IRIS["thrust_coefficient"])) ** 0.5


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


def target(xyz) -> dict[str, float]:
    return dict(zip(("target_x", "target_y", "target_z"), xyz, strict=True))


def open_plant_inputs(rotors: int) -> tuple[str, ...]:
    """No external wind, healthy motors: the inputs a plant keeps at their start values."""
    wind = ("wind_input_x", "wind_input_y", "wind_input_z")
    return (*wind, *(f"motor_effectiveness_{i}" for i in range(rotors)))


def policy_pair(plant, rotors, vehicle, hover, policy, goal) -> tuple[Component, Component]:
    """A plant FMU (`vehicle` parameters, at rest at POLICY_START_Z with its motors at
    `hover`, no wind) and a Policy.fmu flying it to `goal`, as the gym's episode starts."""
    start = {"seed": 1, "initial_z": POLICY_START_Z, "initial_motor": hover, "wind_enabled": 0}
    return (
        Component("plant", plant, {**vehicle, **start}, open_inputs=open_plant_inputs(rotors)),
        Component("policy", policy, {**target(goal), "initial_motor": hover}),
    )


PLANT = Component(
    "plant",
    "Quadrotor.fmu",
    {"seed": 1, "initial_z": START_Z, "initial_motor": HOVER, "wind_enabled": 0},
    open_inputs=open_plant_inputs(4),
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
    # (c) Hexacopter + Policy.fmu (policies/hexa_hover, motor commands): the gym episode of
    # seed HEXA_SEED, from 1.5 m to its target; the policy acts every 20 ms. 5 ms is the
    # plant's physics grid, so each communication step is whole RK4 steps, as in the gym.
    "policy_hover": System(
        "policy_hover",
        "Hexacopter.fmu flown to a target by a trained policy (HexaHoverPolicy.fmu: "
        "policies/hexa_hover, ONNX in tract) writing the six motor commands",
        (*policy_pair("Hexacopter.fmu", 6, {}, HEXA_HOVER, "HexaHoverPolicy.fmu", HEXA_TARGET),),
        stop_time=5.0,
        step_size=0.005,
    ),
    # (d) Quadrotor (the Iris) + RateController + Policy.fmu (policies/px4_offboard_hover):
    # the policy PX4 flies in offboard mode, writing RateController's setpoint by name from
    # the plant's state (the estimate of an FMU system); the gym episode of OFFBOARD_SEED.
    "offboard_policy": System(
        "offboard_policy",
        "Quadrotor.fmu (the Iris) flown through PX4's rate loop (RateController.fmu) by the "
        "PX4 offboard rates policy (OffboardPolicy.fmu: policies/px4_offboard_hover) to a target",
        (
            *policy_pair(
                "Quadrotor.fmu", 4, IRIS, IRIS_HOVER, "OffboardPolicy.fmu", OFFBOARD_TARGET
            ),
            RATES,
        ),
        stop_time=5.0,
        step_size=0.004,
    ),
}

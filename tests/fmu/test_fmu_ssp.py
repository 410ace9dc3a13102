"""examples/ssp: the SSP systems built from the packed FMUs hold their targets in fmpy's SSP
support, in ecos (ecospy) and in libcosim (libcosimpy), and the engines agree: ecos and
libcosim bit for bit (the same fixed-step master), fmpy within a tolerance.

Tolerance between engines: final positions within 1 mm and yaw within 1 mrad (measured:
0.14 mm, 0.03 mrad). The engines start differently: fmpy's connectors start at 0, so its
first 4 ms fly on zero motor commands and a zero setpoint (a 3.3 cm dip the loop recovers
from), where ecos moves the start values along the connections during initialisation; a
closed loop forgets its start only up to PX4's PWM step (0.001 on each motor command), so the
two runs end close, not bit for bit equal.

The policy systems (policy_hover: Hexacopter + HexaHoverPolicy; offboard_policy: Quadrotor +
RateController + OffboardPolicy) fly a gym episode (the seed's start and target) and are
compared with it every control step (20 ms). Tolerance: within 5 cm all along and 1 cm at the
end (measured: 2.8 cm / 5.0 mm for policy_hover in fmpy, 1.3 cm / 5.1 mm in ecos and libcosim;
4.1 cm / 3.1 mm for offboard_policy in fmpy, 3.9 mm / 2.3 mm in ecos and libcosim). Why not
closer: every connection of these fixed-step masters delays by one communication step (5 ms
and 4 ms), where the gym's policy acts on the state of the same instant, and fmpy flies its
first step on zero inputs; the policies, stiff in their first half second, turn those
milliseconds into centimetres that the closed loop then removes. tract's float32 network
(within 1.7e-6 of torch) accounts for under 1e-4 m of it (test_fmu_policy.py and
test_fmu_offboard_policy.py fly the same FMUs in the gym's order).
"""

import importlib.util
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy.validation import validate_fmu
from policy_episodes import hexa_episode, offboard_episode

ROOT = Path(__file__).resolve().parents[2]
SSP = ROOT / "examples" / "ssp"


def load(file):
    sys.path.insert(0, str(SSP))
    spec = importlib.util.spec_from_file_location(file.removesuffix(".py"), SSP / file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build, engines, systems = load("build.py"), load("engines.py"), load("systems.py")


POLICY_SYSTEMS = ("policy_hover", "offboard_policy")
TRAJECTORY_TOLERANCE_M = 0.05
FINAL_TOLERANCE_M = 0.01


@pytest.fixture(scope="module")
def runs(fmus, policy_fmus, tmp_path_factory):
    """Every system in every engine: {(system, engine): watched outputs}."""
    out = tmp_path_factory.mktemp("ssp")
    paths = build.main(["--fmus", str(fmus["Quadrotor"].parent), "--out", str(out)])
    assert [p.name for p in paths] == [f"{name}.ssp" for name in systems.SYSTEMS]
    result = {}
    for name, system in systems.SYSTEMS.items():
        for engine in engines.ENGINES:
            ssp = out / f"{name}.ssp"
            result[name, engine] = engines.run(
                ssp, engine, system.stop_time, system.step_size, system.watch
            )
    return result


@pytest.fixture(scope="module")
def gym():
    """The gym episodes the policy systems fly: {system: episode}."""
    return {
        "policy_hover": hexa_episode(systems.HEXA_SEED),
        "offboard_policy": offboard_episode(systems.OFFBOARD_SEED),
    }


def final(run, name):
    # fmpy's running-sum time takes one step past the stop time; compare at the stop time.
    at = int(np.argmin(np.abs(run["time"] - 6.0))) if run["time"][-1] > 5 else -1
    return run[name][at]


@pytest.mark.parametrize("engine", engines.ENGINES)
def test_attitude_controller_holds_the_hover_and_the_yaw_step(runs, engine):
    run = runs["attitude_hover", engine]
    assert abs(run["time"][-1] - 6.0) < 5e-3
    # Level hover at 1 m until the step at 2 s (fmpy: after its start dip).
    before = int(np.argmin(np.abs(run["time"] - 2.0)))
    assert abs(run["plant.yaw"][before]) < 1e-9
    assert abs(run["plant.z"][before] - 1.0) < 5e-3
    # Then 0.5 rad of yaw, in place.
    assert abs(final(run, "plant.yaw") - 0.5) < 1e-3
    for name, target in (("plant.x", 0.0), ("plant.y", 0.0), ("plant.z", 1.0)):
        assert abs(final(run, name) - target) < 1e-2, (name, final(run, name))


@pytest.mark.parametrize("system", list(systems.SYSTEMS))
def test_ecos_and_libcosim_fly_the_same_bits(runs, system):
    ecos, libcosim = runs[system, "ecos"], runs[system, "libcosim"]
    for name in systems.SYSTEMS[system].watch:
        assert ecos[name].tobytes() == libcosim[name].tobytes(), name


def test_both_engines_end_the_attitude_step_alike(runs):
    fmpy, ecos = runs["attitude_hover", "fmpy"], runs["attitude_hover", "ecos"]
    for name in ("plant.x", "plant.y", "plant.z"):
        assert abs(final(fmpy, name) - final(ecos, name)) < 1e-3, name
    assert abs(final(fmpy, "plant.yaw") - final(ecos, "plant.yaw")) < 1e-3


@pytest.mark.parametrize("engine", engines.ENGINES)
def test_constant_setpoint_keeps_the_vehicle_level_in_place(runs, engine):
    run = runs["rates_hover", engine]
    for name in ("plant.x", "plant.y", "plant.yaw"):
        assert np.abs(run[name]).max() < 1e-9, name
    # Open loop in height: PX4's PWM step rounds the hover command 0.49523 down to 0.495, so
    # the vehicle sinks at g (1 - (0.495 / 0.49523)^2) = 9.0 mm/s^2 (ecos: 40.5 mm in 3 s, and
    # ~2 mm more while the motors settle); fmpy's zero-command first step costs it ~7 cm/s more.
    sink = 0.5 * 9.81 * (1 - (0.495 / systems.HOVER) ** 2) * 3.0**2
    ecos_z = runs["rates_hover", "ecos"]["plant.z"][-1]
    assert abs((1.0 - ecos_z) - sink) < 3e-3, ecos_z
    assert 0.6 < run["plant.z"][-1] <= ecos_z + 1e-12


def test_the_policy_systems_fly_the_gyms_start_and_target(gym):
    for name, target in (
        ("policy_hover", systems.HEXA_TARGET),
        ("offboard_policy", systems.OFFBOARD_TARGET),
    ):
        assert gym[name]["target"].tolist() == list(target), name
        assert gym[name]["positions"][0].tolist() == [0.0, 0.0, systems.POLICY_START_Z], name


@pytest.mark.parametrize("engine", engines.ENGINES)
@pytest.mark.parametrize("system", POLICY_SYSTEMS)
def test_a_policy_system_flies_the_gym_episode_to_its_target(runs, gym, system, engine):
    run, episode = runs[system, engine], gym[system]
    # The engine's outputs at the gym's control steps k·dt (fmpy's times are running sums).
    steps = np.arange(1, len(episode["positions"])) * episode["dt"]
    at = [int(np.argmin(np.abs(run["time"] - t))) for t in steps]
    assert np.abs(run["time"][at] - steps).max() < 1e-9
    flown = np.stack([run[f"plant.{c}"][at] for c in "xyz"], axis=1)
    deviation = np.linalg.norm(flown - episode["positions"][1:], axis=1)
    end = np.linalg.norm(flown[-1] - episode["target"])
    print(
        f"{system} in {engine}: {deviation.max():.4f} m from the gym at most, "
        f"{deviation[-1]:.4f} m at the end; {end:.4f} m from the target"
    )
    assert deviation.max() < TRAJECTORY_TOLERANCE_M
    assert deviation[-1] < FINAL_TOLERANCE_M
    # It held the target as the gym episode did (both end within 7.1 cm of it).
    assert end < 0.1
    assert np.linalg.norm(episode["target"] - episode["positions"][0]) > 0.9, "it flew"


def test_a_system_that_cannot_be_wired_is_refused_naming_the_variable(fmus, tmp_path):
    folder = fmus["Quadrotor"].parent
    rates = systems.Component("rates", "RateController.fmu", {"MC_ROLLRATE_PP": 0.1})
    bad = systems.System("bad", "", (systems.PLANT, rates), stop_time=1.0, step_size=0.004)
    with pytest.raises(
        build.WiringError, match="RateController.fmu has no variable `MC_ROLLRATE_PP`"
    ):
        build.build(bad, folder, tmp_path)
    # Two FMUs offering motor_command_0: wiring by name needs one.
    twice = systems.System(
        "twice",
        "",
        (systems.PLANT, systems.RATES, systems.Component("r2", "RateController.fmu")),
        1.0,
        0.004,
    )
    with pytest.raises(
        build.WiringError,
        match="input `motor_command_0` of Quadrotor.fmu is an output of rates, r2",
    ):
        build.build(twice, folder, tmp_path)
    # An input nothing feeds: refused unless bound or listed as open.
    alone = systems.System(
        "alone", "", (systems.PLANT, systems.Component("a", "AttitudeController.fmu")), 1.0, 0.004
    )
    with pytest.raises(
        build.WiringError,
        match="input `motor_command_0` of Quadrotor.fmu \\(plant\\) is fed by no output",
    ):
        build.build(alone, folder, tmp_path)
    missing = systems.System(
        "missing", "", (systems.PLANT, systems.Component("p", "Policy.fmu")), 1.0, 0.004
    )
    with pytest.raises(build.WiringError, match="Policy.fmu \\(component p\\) does not exist"):
        build.build(missing, folder, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_a_policy_wired_to_the_wrong_plant_is_refused_naming_the_input(fmus, policy_fmus, tmp_path):
    """The hexa policy reads motor_state_0..5; Quadrotor.fmu has four motors, so nothing
    feeds motor_state_4: refused naming it, before anything is written."""
    plant, policy = systems.policy_pair(
        "Quadrotor.fmu", 4, {}, systems.HOVER, "HexaHoverPolicy.fmu", systems.HEXA_TARGET
    )
    wrong = systems.System("wrong", "", (plant, policy), 1.0, 0.005)
    with pytest.raises(
        build.WiringError,
        match="input `motor_state_4` of HexaHoverPolicy.fmu \\(policy\\) is fed by no output",
    ):
        build.build(wrong, fmus["Quadrotor"].parent, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_a_binding_of_a_type_ssp_cannot_carry_is_refused_naming_it():
    policy = systems.Component("p", "Policy.fmu", {"mode": 1, "gain": 2})
    table = {"mode": ("parameter", "String"), "gain": ("parameter", "Integer")}
    with pytest.raises(build.WiringError, match="`mode` of Policy.fmu is a String"):
        build.parameter_xml(policy, table)
    table["mode"] = ("parameter", "Boolean")
    xml = build.parameter_xml(policy, table)
    assert '<ssv:Boolean value="true"/>' in xml and '<ssv:Integer value="2"/>' in xml


def test_the_archive_holds_the_ssd_and_each_fmu_once(runs, fmus, tmp_path):
    path = build.build(systems.SYSTEMS["attitude_hover"], fmus["Quadrotor"].parent, tmp_path)
    names = sorted(zipfile.ZipFile(path).namelist())
    assert names == [
        "SystemStructure.ssd",
        "resources/AttitudeController.fmu",
        "resources/Quadrotor.fmu",
        "resources/RateController.fmu",
    ]


def test_the_plot_shows_both_systems_in_both_engines(fmus, tmp_path):
    out = load("plot.py").main(
        ["--fmus", str(fmus["Quadrotor"].parent), "--out", str(tmp_path / "p.png")]
    )
    assert out.stat().st_size > 30_000


def test_attitude_controller_validates_in_fmpy(fmus):
    for name in ("AttitudeController", "AttitudeController-fmi3"):
        assert validate_fmu(str(fmus[name])) == [], name


def test_engines_refuse_a_connection_to_a_missing_variable_naming_it(fmus, tmp_path):
    good = build.build(systems.SYSTEMS["attitude_hover"], fmus["Quadrotor"].parent, tmp_path)
    with zipfile.ZipFile(good) as z:
        files = {n: z.read(n) for n in z.namelist()}
    ssd = files["SystemStructure.ssd"].decode()
    wire = 'startConnector="yaw" endElement="attitude"'
    assert wire in ssd
    files["SystemStructure.ssd"] = ssd.replace(wire, 'startConnector="yaww" endElement="attitude"')
    bad = tmp_path / "bad.ssp"
    with zipfile.ZipFile(bad, "w") as z:
        for name, data in files.items():
            z.writestr(name, data)
    with pytest.raises(Exception, match="No connector named: 'yaww' defined for element: 'plant'"):
        engines.run(bad, "ecos", 0.1, 0.004, ["plant.z"])
    with pytest.raises(KeyError, match="attitude_hover.plant.yaww"):
        engines.run(bad, "fmpy", 0.1, 0.004, ["plant.z"])

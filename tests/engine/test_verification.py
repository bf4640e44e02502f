"""Verification of the contact law against closed-form results (PHYSICS.md section 7).

Chung & Ooi (2011) cases 1-3, the Coulomb and EPSD2 limits, SJKR cohesion, energy conservation
and determinism, each on the real engine.
"""

import math

import numpy as np
import pytest

from .conftest import header, material_block, run_engine

pytestmark = pytest.mark.engine


def hertz_impact(y_star: float, r_star: float, m_star: float, v: float) -> dict:
    """Hertz theory for an elastic normal impact at relative speed v (m, N, s)."""
    delta = (15.0 * m_star * v**2 / (16.0 * y_star * math.sqrt(r_star))) ** 0.4
    force = 4.0 / 3.0 * y_star * math.sqrt(r_star) * delta**1.5
    return {"delta": delta, "force": force, "time": 2.9432 * delta / v}


def two_sphere_deck(
    radius, density, youngs, poisson, restitution, speed, dt, steps, every=1, friction=0.0, extra=""
):
    gap = 0.02 * radius
    x = radius + 0.5 * gap
    return (
        header(half_width=20 * radius)
        + material_block(youngs, poisson, restitution, friction)
        + f"""pair_style gran model hertz tangential history
pair_coeff * *
timestep {dt!r}
create_atoms 1 single {-x!r} 0 0 units box
create_atoms 1 single {x!r} 0 0 units box
set atom 1 diameter {2 * radius!r} density {density!r} vx {speed!r}
set atom 2 diameter {2 * radius!r} density {density!r} vx {-speed!r}
group a id 1
group b id 2
fix integr all nve/sphere
{extra}
variable overlap equal {2 * radius!r}-(xcm(b,x)-xcm(a,x))
variable force equal fcm(b,x)
variable vrel equal vcm(b,x)-vcm(a,x)
thermo_style custom step time v_overlap v_force v_vrel
thermo {every}
run {steps}
"""
    )


def test_case1_head_on_impact_matches_hertz(tmp_path):
    # Glass spheres, R = 10 mm, +-10 m/s (Chung & Ooi 2011, case 1).
    r, rho, y, nu, v = 0.01, 2800.0, 4.8e10, 0.20, 10.0
    deck = two_sphere_deck(r, rho, y, nu, 1.0, v, dt=1e-8, steps=8000)
    t = run_engine(tmp_path, deck).thermo()[0]
    m = 4.0 / 3.0 * math.pi * r**3 * rho
    theory = hertz_impact(y / (2 * (1 - nu**2)), r / 2, m / 2, 2 * v)
    assert theory["delta"] == pytest.approx(274e-6, rel=0.01)  # the published figure
    assert t["v_overlap"].max() == pytest.approx(theory["delta"], rel=0.01)
    assert t["v_force"].max() == pytest.approx(theory["force"], rel=0.01)
    contact_time = (t["v_overlap"] > 0).sum() * 1e-8
    assert contact_time == pytest.approx(theory["time"], rel=0.01)
    # Elastic: the spheres separate at the speed they met.
    assert t["v_vrel"].iloc[-1] == pytest.approx(2 * v, rel=1e-3)


@pytest.mark.parametrize("restitution", [0.2, 0.4, 0.6, 0.8, 1.0])
def test_case3_restitution_particle_particle(tmp_path, restitution):
    r, rho, y, nu, v = 0.01, 2800.0, 4.8e10, 0.20, 1.0
    deck = two_sphere_deck(r, rho, y, nu, restitution, v, dt=2e-8, steps=12000, every=100)
    t = run_engine(tmp_path, deck).thermo()[0]
    assert t["v_overlap"].iloc[-1] < 0  # separated again
    e_out = t["v_vrel"].iloc[-1] / (2 * v)
    assert e_out == pytest.approx(restitution, rel=0.01)


def wall_deck(
    radius,
    density,
    youngs,
    poisson,
    restitution,
    friction,
    dt,
    steps,
    every,
    z0,
    vx=0.0,
    vz=0.0,
    gravity=None,
    rolling=None,
    wall_youngs=None,
    extra="",
):
    """One sphere above a zplane wall of atom type 2."""
    model = "model hertz tangential history"
    if rolling is not None:
        model += " rolling_friction epsd2"
    grav = ""
    if gravity is not None:
        gx, gy, gz = gravity
        grav = f"fix grav all gravity 9.81 vector {gx!r} {gy!r} {gz!r}\n"
    return (
        header(half_width=max(50 * radius, 1.0), ntypes=2)
        + material_block(
            [youngs, wall_youngs or youngs],
            [poisson, poisson],
            restitution,
            friction,
            rolling=rolling,
            ntypes=2,
        )
        + f"""pair_style gran {model}
pair_coeff * *
timestep {dt!r}
create_atoms 1 single 0 0 {z0!r} units box
set atom 1 diameter {2 * radius!r} density {density!r} vx {vx!r} vz {vz!r}
fix floor all wall/gran {model} primitive type 2 zplane 0.0
fix integr all nve/sphere
{grav}{extra}
variable overlap equal {radius!r}-xcm(all,z)
variable force equal fcm(all,z)
variable vx equal vcm(all,x)
variable vz equal vcm(all,z)
variable x equal xcm(all,x)
thermo_style custom step time v_overlap v_force v_vx v_vz v_x
thermo {every}
run {steps}
"""
    )


def test_case2_sphere_on_rigid_wall_matches_hertz(tmp_path):
    # Aluminium sphere, R = 0.1 m, 0.2 m/s onto a (nearly) rigid wall (Chung & Ooi 2011, case 2).
    r, rho, y, nu, v = 0.1, 2699.0, 7.0e10, 0.30, 0.2
    deck = wall_deck(
        r,
        rho,
        y,
        nu,
        1.0,
        0.0,
        dt=1e-7,
        steps=12000,
        every=1,
        z0=r * 1.0002,
        vz=-v,
        wall_youngs=1e17,
    )
    t = run_engine(tmp_path, deck).thermo()[0]
    m = 4.0 / 3.0 * math.pi * r**3 * rho
    theory = hertz_impact(y / (1 - nu**2), r, m, v)
    assert theory["force"] == pytest.approx(11.4e3, rel=0.02)  # published figures
    assert theory["time"] == pytest.approx(0.73e-3, rel=0.02)
    assert t["v_overlap"].max() == pytest.approx(theory["delta"], rel=0.01)
    assert t["v_force"].max() == pytest.approx(theory["force"], rel=0.01)
    assert (t["v_overlap"] > 0).sum() * 1e-7 == pytest.approx(theory["time"], rel=0.01)


@pytest.mark.parametrize("restitution", [0.2, 0.5, 0.8, 1.0])
def test_case3_restitution_particle_wall(tmp_path, restitution):
    r = 0.01
    deck = wall_deck(
        r,
        2800.0,
        4.8e10,
        0.2,
        restitution,
        0.0,
        dt=2e-8,
        steps=20000,
        every=100,
        z0=r * 1.01,
        vz=-1.0,
    )
    t = run_engine(tmp_path, deck).thermo()[0]
    assert t["v_overlap"].iloc[-1] < 0
    assert t["v_vz"].iloc[-1] == pytest.approx(restitution * 1.0, rel=0.01)


def test_sliding_sphere_ends_rolling_at_five_sevenths(tmp_path):
    r, v0 = 0.005, 2.0
    deck = wall_deck(
        r,
        2500.0,
        1e8,
        0.3,
        0.5,
        0.3,
        dt=5e-6,
        steps=120000,
        every=2000,
        z0=r * 0.9995,
        vx=v0,
        gravity=(0.0, 0.0, -1.0),
    )
    t = run_engine(tmp_path, deck).thermo()[0]
    # Slip ends at t = 2 v0 / (7 mu g) = 0.19 s; the last 0.2 s are pure rolling.
    tail = t[t["Time"] > 0.4]
    assert tail["v_vx"].to_numpy() == pytest.approx(5.0 / 7.0 * v0, rel=0.01)


def _incline(tmp_path, theta_deg, mu_s, mu_r, seconds=0.3):
    r = 0.005
    th = math.radians(theta_deg)
    deck = wall_deck(
        r,
        2500.0,
        1e8,
        0.3,
        0.5,
        mu_s,
        dt=5e-6,
        steps=int(seconds / 5e-6),
        every=1000,
        z0=r * 0.9995,
        gravity=(math.sin(th), 0.0, -math.cos(th)),
        rolling=mu_r,
    )
    return run_engine(tmp_path, deck).thermo()[0], r


def test_coulomb_cap_sticks_below_and_slides_above_friction_angle(tmp_path):
    mu_s = 0.5  # friction angle 26.6 deg; rolling blocked by mu_r = 10
    stuck, r = _incline(tmp_path / "stick", 20.0, mu_s, 10.0)
    assert abs(stuck["v_x"].iloc[-1]) < 1e-3 * r
    sliding, _ = _incline(tmp_path / "slide", 35.0, mu_s, 10.0, seconds=0.2)
    th = math.radians(35.0)
    a = 9.81 * (math.sin(th) - mu_s * math.cos(th))
    late = sliding.iloc[-1]
    assert late["v_vx"] == pytest.approx(a * late["Time"], rel=0.02)


def test_epsd2_holds_sphere_while_mu_r_exceeds_tan_theta(tmp_path):
    theta = 20.0  # tan = 0.364; sliding prevented by mu_s = 1
    held, r = _incline(tmp_path / "held", theta, 1.0, 0.45)
    assert abs(held["v_x"].iloc[-1]) < 1e-2 * r
    rolls, _ = _incline(tmp_path / "rolls", theta, 1.0, 0.25)
    assert rolls["v_x"].iloc[-1] > 5 * r


def test_epsd2_torque_is_capped_at_mu_r_r_fn(tmp_path):
    # A spinning sphere on a frictionless plane: only the rolling torque acts, so
    # I dw/dt = -mu_r R m g  ->  w(t) = w0 - 2.5 mu_r g t / R.
    r, mu_r, w0 = 0.005, 0.3, 200.0
    deck = wall_deck(
        r,
        2500.0,
        1e8,
        0.3,
        0.5,
        0.0,
        dt=5e-6,
        steps=20000,
        every=2000,
        z0=r * 0.9995,
        gravity=(0.0, 0.0, -1.0),
        rolling=mu_r,
        extra=f"set atom 1 omegay {w0!r}\ncompute rot all erotate/sphere\n"
        "variable erot equal c_rot",
    )
    deck = deck.replace("v_x\n", "v_x v_erot\n")
    t = run_engine(tmp_path, deck).thermo()[0]
    m = 4.0 / 3.0 * math.pi * r**3 * 2500.0
    inertia = 0.4 * m * r**2
    w = np.sqrt(2 * t["v_erot"].to_numpy() / inertia)
    late = t["Time"].to_numpy() > 0.02
    slope = np.polyfit(t["Time"].to_numpy()[late], w[late], 1)[0]
    assert slope == pytest.approx(-2.5 * mu_r * 9.81 / r, rel=0.01)


def test_sjkr_force_equals_k_times_contact_area(tmp_path):
    r, dist, k = 0.01, 0.0195, 2.0e5
    forces = {}
    for cohesion in (False, True):
        model = "model hertz tangential history" + (" cohesion sjkr" if cohesion else "")
        deck = (
            header(half_width=0.1)
            + material_block(1e7, 0.3, 0.5, 0.5, cohesion=k if cohesion else None)
            + f"""pair_style gran {model}
pair_coeff * *
timestep 1e-6
create_atoms 1 single 0 0 0 units box
create_atoms 1 single {dist!r} 0 0 units box
set group all diameter {2 * r!r} density 2500
group b id 2
variable force equal fcm(b,x)
thermo_style custom step v_force
run 0
"""
        )
        forces[cohesion] = run_engine(tmp_path / str(cohesion), deck).thermo()[0]["v_force"].iloc[0]
    area = math.pi * (r**2 - dist**2 / 4)
    assert forces[False] - forces[True] == pytest.approx(k * area, rel=1e-9)


def _gas_deck(
    n_side=6, spacing=0.03, radius=0.01, restitution=1.0, friction=0.0, steps=40000, seed=1
):
    rng = np.random.default_rng(seed)
    lines = []
    half = n_side * spacing / 2
    for i in range(n_side):
        for j in range(n_side):
            for k in range(n_side):
                x, y, z = (-half + (a + 0.5) * spacing for a in (i, j, k))
                lines.append(
                    f"create_atoms 1 single {float(x)!r} {float(y)!r} {float(z)!r} units box"
                )
    sets = [
        f"set atom {n + 1} vx {float(vx)!r} vy {float(vy)!r} vz {float(vz)!r}"
        for n, (vx, vy, vz) in enumerate(rng.normal(0.0, 1.0, size=(n_side**3, 3)))
    ]
    return (
        header(half_width=half, boundary="p p p")
        + material_block(1e7, 0.3, restitution, friction)
        + "pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 2e-6\n"
        + "\n".join(lines)
        + f"\nset group all diameter {2 * radius!r} density 2500\n"
        + "\n".join(sets)
        + f"\nfix integr all nve/sphere\nthermo_style custom step ke\nthermo 200\nrun {steps}\n"
    )


def test_kinetic_energy_never_rises_in_elastic_frictionless_box(tmp_path):
    t = run_engine(tmp_path, _gas_deck()).thermo()[0]
    ke = t["KinEng"].to_numpy()
    assert (ke <= ke[0] * (1 + 1e-6)).all()
    assert ke.min() < ke[0] * 0.999  # contacts did happen and stored elastic energy


def test_dissipative_gas_loses_energy_monotonically_on_average(tmp_path):
    t = run_engine(tmp_path, _gas_deck(restitution=0.7, friction=0.5)).thermo()[0]
    ke = t["KinEng"].to_numpy()
    assert (ke <= ke[0] * (1 + 1e-6)).all()
    assert ke[-1] < 0.8 * ke[0]

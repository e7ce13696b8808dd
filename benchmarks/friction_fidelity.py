"""The friction-fidelity contract of the simulated arm as a table (docs/execution.md, "Friction fidelity"):
the arm's contact setting against the contract's limits, and, with --stiff, the setting it
replaced (the solver's stiff friction on every pad point, sliding or not).

    python3 benchmarks/friction_fidelity.py [--engine mujoco|drake] [--stiff]
        [--robot FILE --flange LINK --tcp X Y Z RX RY RZ [--base X Y Z YAW]] [--timestep-ms MS]

The rigs hold the jaws on a kinematic hand; --robot runs the contract's last part, the pivot on
the arm, on that arm (docs/execution.md, "Bring your own arm").
"""
import argparse
import time

from shipped import TASKS

from stablepush.kinematics import cell_model
from stablepush.sim import fidelity
from stablepush.sim.engines import DEFAULT_ENGINE, ENGINES
from stablepush.sim.mujoco import friction
from stablepush.task import check_push, load_task, with_robot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--stiff", action="store_true", help="measure the solver's stiff pad friction alone (no pad point ever slides with explicit friction)")
    parser.add_argument("--engine", choices=ENGINES, default=DEFAULT_ENGINE, help="the physics engine (default mujoco)")
    parser.add_argument("--timestep-ms", type=float, default=None, metavar="MS",
                        help="MuJoCo's time step for this run (default: kinematics.cell_model.TIMESTEP, the contract's)")
    parser.add_argument("--robot", metavar="FILE", help="the arm of the pivot on the arm: a URDF or MJCF file")
    parser.add_argument("--flange", metavar="LINK", help="with --robot: the link the jaws mount on")
    parser.add_argument("--tcp", nargs=6, type=float, metavar=("X", "Y", "Z", "RX", "RY", "RZ"),
                        help="with --robot: G in the flange's frame, mm and rpy deg")
    parser.add_argument("--base", nargs=4, type=float, metavar=("X", "Y", "Z", "YAW"), help="the arm's base, mm and deg")
    args = parser.parse_args()
    engine = args.engine
    if args.stiff and engine != "mujoco":
        parser.error("--stiff is MuJoCo's setting: the pads' friction is Drake's own")
    if args.stiff:
        friction.SLIDE_SPEED = float("inf")
    if args.timestep_ms is not None:
        if engine != "mujoco":
            parser.error("--timestep-ms is MuJoCo's step (Drake's is sim.drake.arm.DRAKE_TIMESTEP)")
        cell_model.TIMESTEP = args.timestep_ms / 1e3
    started = time.perf_counter()
    print(f"engine: {engine}" + (f", {cell_model.TIMESTEP * 1e3:g} ms step" if engine == "mujoco" else "") + "\n")
    print("| wall load | pad speed mm/s | creep um per mm (limit) | pad friction / mu N | pad drop-out steps | steps/s |")
    print("|---:|---:|---:|---:|---:|---:|")
    for load in (0.5, 0.9):
        for speed in (0.001, 0.005, 0.02):
            r = fidelity.wall_creep(load, speed, engine=engine)
            print(f"| {load:.0%} | {r.pad_speed_mm_s:g} | {r.creep_um_per_mm:.3f} ({fidelity.CREEP_LIMIT_UM_PER_MM[load]:g}) "
                  f"| {r.pad_friction_ratio:.4f} | {r.pad_dropout_steps} | {r.steps_per_s:.0f} |", flush=True)
    print()
    print("| static hold, weight / 2 mu N | moved in 1 s, um (limit) |")
    print("|---:|---:|")
    for load in (0.5, 0.9):
        r = fidelity.static_hold(load, engine=engine)
        print(f"| {load:.0%} | {r.moved_um:.2f} ({fidelity.HOLD_LIMIT_UM:g}) |", flush=True)
    print()
    print("| pivot about the pad centre, 30 deg | model | prism moved in the world mm | rotated deg |")
    print("|---|---|---:|---:|")
    pivoting = load_task(TASKS / "pivoting.yaml")
    for mu in (0.6, 0.2):
        task = fidelity.with_pusher_mu(pivoting, "left", mu)
        stable = check_push(task, (0, 0, 0), (0, 0, 1), "left")["left"]["feasible"]
        r = fidelity.pivot(task, "left", turn_deg=30, engine=engine)
        print(f"| pivoting, left pusher mu {mu} | {'stable' if stable else 'not stable'} | {r.moved_mm:.3f} "
              f"| {r.rotated_deg:+.3f} |", flush=True)
    print()
    on_arm = with_robot(pivoting, args.robot, args.flange, args.tcp, args.base)
    print(f"arm: {on_arm.environment.robot.model or 'the shipped arm'}")
    r = fidelity.pivot_on_arm(on_arm, engine=engine)
    print(
        f"Pivot on the arm, first {r.pushes} pushes of the pivoting plan: {r.error_mm:.3f} mm, {r.error_deg:+.3f} deg "
        f"from the plan (limits {fidelity.ARM_PIVOT_LIMIT_MM} mm, {fidelity.ARM_PIVOT_LIMIT_DEG} deg), {r.steps_per_s:.0f} steps/s"
    )
    print(f"\n{time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()

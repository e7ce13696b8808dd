"""`stablepush sim-arm`."""
from __future__ import annotations

from dataclasses import dataclass

import click

from stablepush.execution import DEFAULT_PORT
from stablepush.sim import DEFAULT_ENGINE, ENGINES
from stablepush_cli.groups import RobotChoice, SimWorld, option_group, robot_choice, world_option
from stablepush_cli.options import (
    Finite,
    Whole,
)


@dataclass(frozen=True)
class ServedWorld:
    """--mu-scale, --tracker-noise, --seed, --idle-timeout, --engine, --world: the world the server
    simulates for each client, on which engine, and how long it waits on a silent one."""

    world: SimWorld
    engine: str
    idle_timeout: float


def _served(mu_scale, tracker_noise, seed, idle_timeout, engine, world) -> ServedWorld:
    return ServedWorld(SimWorld(mu_scale, tracker_noise, world, seed), engine, idle_timeout)


@click.command("sim-arm")
@click.option("--host", default="127.0.0.1", show_default=True, help="Address to listen on.")
@click.option("--port", default=DEFAULT_PORT, show_default=True, type=Whole(min=0, max=65535),
              help="Port to listen on (0: any free port, printed).")
@click.option("--exit-after", type=Whole(min=1), default=None, metavar="N",
              help="Fault injection for testing executors: die abruptly after N waypoints.")
@option_group(
    "served", _served,
    click.option("--mu-scale", "mu_scale", default=1.0, show_default=True, type=Finite(min=0.1, max=10),
                 metavar="S", help="The pads' and features' mu are S times each task's (a world unlike the model)."),
    click.option("--tracker-noise", "tracker_noise", nargs=2, type=Finite(min=0), default=(0.0, 0.0),
                 metavar="MM DEG",
                 help="Standard deviations of the tracker's noise on object_in_grasp (x, z mm; theta deg)."),
    click.option("--seed", default=0, show_default=True, type=Whole(min=0, max=2**32 - 1),
                 help="Seed of the tracker's noise."),
    click.option("--idle-timeout", default=30.0, show_default=True, type=Finite(min=0.1, max=3600), metavar="S",
                 help="Drop a client that sends no complete message for S seconds (the arm is stopped)."),
    click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
                 help="The physics engine. mujoco: pads slide with stablepush's own Coulomb friction; drake: "
                      "Drake's contact solver alone decides stick and slip (about half MuJoCo's speed)."),
    world_option("The"))
@robot_choice
def sim_arm(host: str, port: int, exit_after, served: ServedWorld, robot: RobotChoice) -> None:
    """Serve a simulated arm (MuJoCo or Drake) over the arm protocol, until interrupted.

    A 7-joint arm of simple shapes (shipped MJCF), or yours (--robot, --flange, --tcp, --base), with
    the project's parallel-jaw gripper whose pads press with the task's grip force; the executor's
    hello carries the object, the features and the friction.
    One session at a time (a second client is told the arm is busy); each starts from a fresh
    world unless the executor resumes a run (--resume-from). An object outline of more than 64
    vertices is simplified for the simulated world only (the tolerance is logged).
    Joint servos track the streamed waypoints by IK; the simulation steps in lock-step with the stream
    (one waypoint period per waypoint), headless, and reports its steps/s. Each acknowledgement carries
    the object's pose in the grasp as a tracker would (`object_in_grasp`), with --tracker-noise.
    With --world the world keeps its own friction, grip or mass whatever a client's task says: a
    world to calibrate against, as a real cell is (a pusher's mu applies where a run places its
    feature).

    \b
    Examples:
      stablepush sim-arm --port 47100
      stablepush sim-arm --port 47100 --world gripper.mu=0.3 --world pushers.left.mu=0.25
    """
    from stablepush.sim import SimArmServer

    server = SimArmServer(host, port, exit_after=exit_after, deviation=served.world.deviation(),
                          idle_timeout=served.idle_timeout, engine=served.engine, robot=robot.arm())
    click.echo(f"sim-arm: listening on {server.host}:{server.port} ({served.engine})", err=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.close()

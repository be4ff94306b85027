"""What sim_node offers beyond the controllers: robot_description, TF and the camera.

:class:`NodeFeatures` declares their parameters, creates their publishers and
is told every /clock period of physics steps; each feature then publishes
whatever is due at the present sim time.  Topics (with the pan/tilt example's files):

* ``/ex_urdf_pan_tilt/robot_description`` -- std_msgs/String, transient local;
* ``/tf``, ``/tf_static`` -- where tf2_msgs is installed;
* ``/ex_urdf_pan_tilt/camera/image_raw`` -- sensor_msgs/Image, rgb8;
* ``/ex_urdf_pan_tilt/camera/camera_info`` -- sensor_msgs/CameraInfo;
* the topics of the sensors the URDF declares (:mod:`.sensor_publishers`).
"""

from __future__ import annotations

from rclpy.node import Node

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.base_pose import FIXED_BASE
from pan_tilt_sim.model.sensors import SensorKind
from pan_tilt_sim.model.world_file import World
from pan_tilt_sim.ros.camera_publisher import CameraPublisher, declare_camera, declare_world
from pan_tilt_sim.ros.robot_state import RobotStatePublisher
from pan_tilt_sim.ros.sensor_publishers import SensorSet, declare_noise_seed
from pan_tilt_sim.sim.camera import Renderer
from pan_tilt_sim.sim.engine import Simulation
from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
from pan_tilt_sim.sim.world import build_world, has_ground


def require_ground(simulation: Simulation, world: str) -> None:
    """Refuse a free base in a world (``world`` parameter's scenery) with no ground."""
    if not simulation.physics.fixed_base and not has_ground(world):
        raise ParameterError(
            f"parameter 'world': '{world}' has no ground for the free base of "
            f"'{simulation.description.name}' to stand on: use 'ground' or 'targets', or weld "
            f"the base with {FIXED_BASE}:=true")


def robot_sensors(node: Node, simulation: Simulation, world: str, namespace_override: str,
                  seed: int | None) -> SensorSet:
    """Publish one robot's URDF/SDF sensors; its <ros2_control> sensors see ``world`` too.

    ``namespace_override`` ('' for none) moves every sensor's topics, as
    spawn's -robot_namespace does; ``seed`` draws their noise (None: the OS's).
    """
    sensors = SensorSet(node, simulation, world, namespace_override=namespace_override,
                        seed=seed)
    # The <ros2_control> sensors: their rays meet this world's ground; their noise, this seed.
    simulation.hardware.configure(world=world, seed=seed)
    return sensors


class NodeFeatures:
    """robot_description, TF and camera of one simulated robot, on ``node``.

    Topics go under ``robot_namespace``; the simulation gives the model, the
    sim time, the joint positions and the PyBullet client the camera renders in.
    """

    def __init__(self, node: Node, simulation: Simulation, robot_namespace: str, *,
                 gui: bool = False, sensor_namespace: str = '',
                 publish_description: bool = True, publish_tf_default: bool = True,
                 world: World | None = None) -> None:
        description = simulation.description
        model = description.model
        self._time_step = simulation.time_step
        # The world parameter's value, when the caller has read it already.
        self.world = world if world is not None else declare_world(node)
        world = self.world.scenery
        require_ground(simulation, world)
        urdf_cameras = any(sensor.kind in (SensorKind.CAMERA, SensorKind.DEPTH)
                           for sensor in model.sensors)
        settings = declare_camera(node, model.link_names, urdf_cameras)
        # The scenery lives in the simulation's client: static bodies the cameras
        # see and the lidars hit (their cost to a physics step is within noise).
        targets = build_world(world, simulation.physics.client_id, ground=gui)
        # The named things in the world, and the world file's objects, spawned now.
        self.entities = Entities(simulation.physics, description.name, targets=targets,
                                 ground=has_ground(world))
        spawn_world_objects(self.entities, self.world)
        seed = declare_noise_seed(node)
        self.noise_seed = seed  # spawned robots' sensors draw from it too
        self.sensors = robot_sensors(node, simulation, world, sensor_namespace, seed)
        self.camera: CameraPublisher | None = None
        static = list(self.sensors.static_frames)
        if settings is not None:
            renderer = Renderer(simulation.physics, model, settings, world)
            self.camera = CameraPublisher(
                node, renderer, lambda: simulation.time,
                naming.join(robot_namespace, 'camera', 'image_raw'),
                naming.join(robot_namespace, 'camera', 'camera_info'))
            static.append((settings.link, settings.optical_frame, self.camera.mount))
        self.robot_state = RobotStatePublisher(
            node, model, description.urdf_xml,
            naming.join(robot_namespace, 'robot_description') if publish_description else None,
            lambda: simulation.time, simulation.joint_positions, static,
            publish_tf_default=publish_tf_default)

    def after_steps(self) -> None:
        """Publish what is due at the present sim time (called every /clock period of steps)."""
        self.robot_state.update()
        if self.camera is not None:
            self.camera.update()
        self.sensors.update()

    def steps_until_due(self, step: int) -> int | None:
        """Return how many steps after ``step`` something watched is due (None: nothing).

        /tf, the camera and the sensors, each only while somebody subscribes:
        the node runs its steps in chunks that end exactly there.
        """
        time_step = self._time_step
        found = [due for due in (self.robot_state.next_step(step, time_step),
                                 self.camera.next_step(step, time_step)
                                 if self.camera is not None else None,
                                 self.sensors.next_step(step)) if due is not None]
        return min(found) - step if found else None

    def refresh_readers(self) -> None:
        """Ask, once per batch of steps, whether anybody reads what is published periodically."""
        self.robot_state.refresh_readers()
        if self.camera is not None:
            self.camera.refresh_readers()

    def remove_robot(self, node: Node) -> None:
        """Take the robot's sensors', camera's and TF's topics away (it left; the world stays)."""
        self.sensors.destroy(node)
        if self.camera is not None:
            self.camera.destroy(node)
            self.camera = None
        self.robot_state.stop()

    def close(self) -> None:
        """Release what the features hold beyond the PyBullet client (temporary files)."""
        self.entities.close()

    def reset(self) -> None:
        """Start every schedule again: sim time was reset, or the world put back."""
        self.robot_state.reset()
        if self.camera is not None:
            self.camera.reset()
        self.sensors.reset()

"""What sim_node offers beyond the controllers: robot_description, TF and the camera.

:class:`NodeFeatures` declares their parameters, creates their publishers and
is told every /clock period of physics steps; each feature then publishes
whatever is due at the present sim time.  Topics (with the seed's files):

* ``/ex_urdf_pan_tilt/robot_description`` -- std_msgs/String, transient local;
* ``/tf``, ``/tf_static`` -- where tf2_msgs is installed;
* ``/ex_urdf_pan_tilt/camera/image_raw`` -- sensor_msgs/Image, rgb8;
* ``/ex_urdf_pan_tilt/camera/camera_info`` -- sensor_msgs/CameraInfo.
"""

from __future__ import annotations

from rclpy.node import Node

from pan_tilt_sim.camera_publisher import CameraPublisher, declare_camera, declare_world
from pan_tilt_sim.engine import Simulation
from pan_tilt_sim.robot_state import RobotStatePublisher
from pan_tilt_sim.world import build_world


class NodeFeatures:
    """robot_description, TF and camera of one simulated robot.

    ``node`` is sim_node's SimNode: it has ``simulation`` and ``topic(*names)``.
    """

    def __init__(self, node: Node, *, gui: bool = False) -> None:
        simulation: Simulation = node.simulation
        world = declare_world(node)
        settings = declare_camera(node, simulation.description.urdf_xml)
        if gui:
            # Show the scenery in the PyBullet window too (visual only: no physics cost).
            build_world(world, simulation.physics.client_id, ground=True)
        self.camera: CameraPublisher | None = None
        static = []
        if settings is not None:
            self.camera = CameraPublisher(
                node, simulation, settings, world,
                node.topic('camera', 'image_raw'), node.topic('camera', 'camera_info'))
            static.append((settings.link, settings.optical_frame, self.camera.mount))
        try:
            self.robot_state = RobotStatePublisher(
                node, simulation, node.topic('robot_description'), static)
        except BaseException:
            self.close()
            raise

    def after_steps(self) -> None:
        """Publish what is due at the present sim time (called every /clock period of steps)."""
        self.robot_state.update()
        if self.camera is not None:
            self.camera.update()

    def close(self) -> None:
        """Release the camera's renderer."""
        if self.camera is not None:
            self.camera.close()
            self.camera = None

"""The live 3D view of the simulation in a browser (``viewer:=true``), served with viser.

viser (a pip package with its web client bundled: no internet, no build
step) serves a page on ``viewer.host``:``viewer.port``.  It shows the robot
as its URDF draws it (:mod:`pan_tilt_sim.model.visuals`), the world's ground,
targets and objects, each link where the simulation has it, the link frames
on request, and the lidars' points and the cameras' images.  Its controls:
pause/play, reset, the real-time factor, and a slider per position-controlled
joint, which publishes on the joint's command topic as a user would
(:mod:`pan_tilt_sim.ros.view_feed`).

Costs: the server and its thread start with sim_node; the scene is built
when the first browser connects.  An update thread, while a browser is
connected, takes a snapshot :data:`FRAME_RATE_HZ` times a second in the
simulation's turn (as a callback does) and sends what moved.  With nobody
connected it waits on an event: nothing is computed for the view, and the
physics loop has no hook for it at all.

This is the only module that imports viser.
"""

from __future__ import annotations

import contextlib
import errno
import io
import threading
import time
from collections.abc import Mapping
from typing import Any

import numpy as np
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.robot import Link, RobotModel
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.model.visuals import VisualMesh, box_mesh, robot_visuals
from pan_tilt_sim.ros.pacing import MAX_REAL_TIME_FACTOR
from pan_tilt_sim.ros.view_feed import (
    VISER_HINT,
    CommandSender,
    Frame,
    SensorTaps,
    SimulationAccess,
    Slider,
    Snapshot,
    ViewerSettings,
    address_error,
    cloud_points,
    command_message,
    frame_poses,
    image_pixels,
    scan_points,
    sensor_topics,
    take_snapshot,
)
from pan_tilt_sim.sim.world import GROUND_RGBA, TARGET_PREFIX, TARGET_SET, has_ground

FRAME_RATE_HZ = 30.0  # scene updates per second while a browser is connected
STATUS_PERIOD_S = 0.25  # wall seconds between updates of the status line
JOIN_TIMEOUT_S = 2.0
GROUND_SIZE = 10.0  # m, the side of the ground grid drawn
AXES_LENGTH = 0.1  # m, a link frame's axes (shown on request)
AXES_RADIUS = 0.004  # m
POINT_SIZE = 0.02  # m, a lidar point
POINT_RGB = (255, 40, 200)
SLIDER_STEP = 0.001  # rad or m
CAMERA_DISTANCE = 3.0  # the browser's camera starts this many robot sizes away
MIN_ROBOT_SIZE = 0.3  # m: a smaller robot is viewed as if it were this big
JPEG_QUALITY = 80
ROBOT_ROOT = '/robot'  # the scene root of the robot the world began with


def import_viser() -> Any:
    """Return the viser module; ParameterError naming the install command where it is missing."""
    try:
        import viser  # noqa: PLC0415 -- an optional dependency, imported on demand
    except ImportError:
        raise ParameterError(VISER_HINT) from None
    return viser


def wxyz(transform: Transform) -> tuple[float, float, float, float]:
    """Return a transform's rotation as viser's (w, x, y, z) quaternion."""
    x, y, z, w = transform.rotation
    return (w, x, y, z)


def rgb255(rgba: tuple[float, ...]) -> tuple[int, int, int]:
    """Return an RGBA colour (0..1) as viser's 0..255 RGB."""
    return tuple(int(round(255 * max(0.0, min(1.0, channel)))) for channel in rgba[:3])


def initial_view(model: RobotModel) -> tuple[tuple[float, float, float],
                                             tuple[float, float, float]]:
    """Return where the browser's camera starts and what it looks at, from the robot's size."""
    origins = np.array([pose.translation for pose in model.link_poses({}).values()])
    low, high = origins.min(axis=0), origins.max(axis=0)
    centre = (low + high) / 2.0
    size = max(float(np.linalg.norm(high - low)), MIN_ROBOT_SIZE)
    eye = centre + size * CAMERA_DISTANCE * np.array([0.7, 0.5, 0.5])
    return tuple(eye.tolist()), tuple(centre.tolist())


class _Body:
    """The scene nodes of one articulated body (the robot or an object): a frame per link."""

    def __init__(self, scene: Any, root: str, model: RobotModel, meshes: list[VisualMesh],
                 show_axes: bool) -> None:
        self.model = model
        self.root = root
        self.links = {}
        self._sent: dict[str, Transform] = {}
        for link in model.link_names:
            self.links[link] = scene.add_frame(f'{root}/{_safe(link)}', show_axes=show_axes,
                                               axes_length=AXES_LENGTH, axes_radius=AXES_RADIUS)
        for mesh in meshes:
            scene.add_mesh_simple(
                f'{root}/{_safe(mesh.link)}/{mesh.name}', mesh.vertices, mesh.faces,
                color=rgb255(mesh.rgba), opacity=mesh.rgba[3] if mesh.rgba[3] < 1.0 else None)

    def move(self, poses: Mapping[str, Transform]) -> None:
        """Send the poses of the links that moved since last time."""
        for link, handle in self.links.items():
            pose = poses.get(link)
            if pose is None or self._sent.get(link) == pose:
                continue
            handle.position = pose.translation
            handle.wxyz = wxyz(pose)
            self._sent[link] = pose

    def show_axes(self, shown: bool) -> None:
        """Show or hide every link's axes."""
        for handle in self.links.values():
            handle.show_axes = shown

    def remove(self) -> None:
        """Take the body out of the scene (each link's frame, with its visuals)."""
        for handle in self.links.values():
            handle.remove()


def _quiet() -> contextlib.AbstractContextManager:
    """Swallow what viser prints on stdout (its banner, "Server stopped")."""
    return contextlib.redirect_stdout(io.StringIO())


def _safe(name: str) -> str:
    """Return ``name`` as one part of a scene-tree name ('/' would nest it)."""
    return name.replace('/', '_') or '_'


class Viewer:
    """The browser view of one sim_node: a viser server and the thread that feeds it."""

    def __init__(self, node: Node, settings: ViewerSettings, *, turns: Any = None,
                 extra_frames: tuple[Frame, ...] = (), camera_image_topic: str | None = None
                 ) -> None:
        viser = import_viser()
        self._node = node
        self._logger = node.get_logger()
        self._model: RobotModel = node.simulation.description.model
        self._source = node.simulation.description.source
        self._extra_frames = tuple(extra_frames)
        self._world = node.features.world.scenery
        self.access = SimulationAccess(node, turns)
        self.sender = CommandSender(node)
        self.taps = SensorTaps(node, sensor_topics(node.features.sensors.publishers,
                                                   camera_image_topic))
        try:
            with _quiet():  # viser prints a banner; sim_node's log line says where instead
                self.server = viser.ViserServer(host=settings.host, port=settings.port,
                                                verbose=False)
        except OSError as err:
            raise address_error(settings, err) from None
        port = self.server.get_port()
        if settings.port and port != settings.port:
            # viser moves to the next free port by itself; the user asked for this one.
            self._stop_server()
            raise address_error(settings, OSError(errno.EADDRINUSE, 'Address already in use'))
        self.settings = ViewerSettings(True, settings.host, port)
        self.frames = 0  # scene updates sent
        # Set while the update thread waits for a browser (and so computes nothing).
        self.idle = threading.Event()
        self._connected = threading.Event()
        self._stopping = False
        self._built = False
        self._latest: Snapshot | None = None
        self._bodies: dict[str, _Body] = {}
        self._sliders: dict[str, Any] = {}
        self._slider_specs: tuple[Slider, ...] = ()
        self._slider_folder: Any = None
        self._images: dict[str, tuple[Any, Any]] = {}  # camera -> (folder, image)
        self._clouds: dict[str, Any] = {}
        self._shown: dict[str, Any] = {}  # the last message drawn, by topic
        self._status: Any = None
        self._status_at = 0.0
        self._pause_button: Any = None
        self._rate: Any = None
        self._show_frames: Any = None
        self._show_sensors: Any = None
        eye, centre = initial_view(self._model)
        self.server.initial_camera.position = eye
        self.server.initial_camera.look_at = centre
        self.server.initial_camera.up = (0.0, 0.0, 1.0)
        self.server.on_client_connect(lambda _client: self._connected.set())
        self.server.on_client_disconnect(lambda _client: self._on_disconnect())
        self._thread = threading.Thread(target=self._run, name='viewer', daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        """The address to open in a browser."""
        return self.settings.url

    @property
    def clients(self) -> int:
        """How many browsers are connected."""
        return len(self.server.get_clients())

    def close(self) -> None:
        """Stop feeding the view and stop the server."""
        self._stopping = True
        self._connected.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(JOIN_TIMEOUT_S)
        self.sender.close()
        self.access.close()
        self._stop_server()

    def _stop_server(self) -> None:
        with _quiet(), contextlib.suppress(Exception):  # already stopped
            self.server.stop()  # waits for its thread, which says it stopped

    # --- the update thread ----------------------------------------------------------------

    def _on_disconnect(self) -> None:
        if not self.server.get_clients():
            self._connected.clear()

    def _run(self) -> None:
        period = 1.0 / FRAME_RATE_HZ
        while not self._stopping:
            if not self.server.get_clients():
                if self.taps.watching:
                    self.access.call(lambda: self.taps.watch(False))
                self.idle.set()
                self._connected.wait()  # nobody watches: nothing to do until someone comes
                continue
            self.idle.clear()
            started = time.monotonic()
            try:
                self.update()
            except Exception as err:  # the view must never take the simulation down
                self._logger.error(f'viewer: {type(err).__name__}: {err}',
                                   throttle_duration_sec=5.0)
            remaining = period - (time.monotonic() - started)
            if remaining > 0 and not self._stopping:
                time.sleep(remaining)

    def update(self) -> None:
        """Take a snapshot and send what changed (the update thread calls it while connected)."""
        snapshot = self.access.call(lambda: take_snapshot(self._node))
        if snapshot is None:
            return
        self._latest = snapshot
        if not self._built:
            self._build(snapshot)
        # The sensors tapped are the first robot's: none to show once it was deleted.
        wanted = (self._show_sensors.value and bool(self.taps.topics)
                  and snapshot.robot_pose is not None)
        if wanted != self.taps.watching:
            self.access.call(lambda: self.taps.watch(wanted))
        with self.server.atomic():
            poses = self._move_robot(snapshot)
            self._move_entities(snapshot)
            self._draw_sensors(poses)
            self._update_controls(snapshot)
        self.frames += 1

    # --- building the scene ---------------------------------------------------------------

    def _build(self, snapshot: Snapshot) -> None:
        scene = self.server.scene
        scene.set_up_direction('+z')
        if has_ground(self._world):
            scene.add_grid('/world/ground', width=GROUND_SIZE, height=GROUND_SIZE,
                           plane_color=rgb255(GROUND_RGBA), plane_opacity=0.35,
                           cell_size=0.5, section_size=1.0)
        meshes, warnings = robot_visuals(self._model, self._source.parent)
        for warning in warnings:
            self._logger.warning(f'viewer: {warning}')
        gui = self.server.gui
        with gui.add_folder('Simulation'):
            self._status = gui.add_markdown('')
            self._pause_button = gui.add_button('Pause')
            self._pause_button.on_click(lambda _event: self.pause(not self._node.paused))
            reset = gui.add_button('Reset')
            reset.on_click(lambda _event: self.reset())
            self._rate = gui.add_number('Real-time factor (0: fastest)',
                                        snapshot.real_time_factor, min=0.0,
                                        max=MAX_REAL_TIME_FACTOR, step=0.1)
            self._rate.on_update(self._set_rate)
        with gui.add_folder('Show'):
            self._show_frames = gui.add_checkbox('Link frames', False)
            self._show_frames.on_update(lambda _event: self._apply_show_frames())
            self._show_sensors = gui.add_checkbox('Lidar points and camera images', True)
        self._bodies[ROBOT_ROOT] = _Body(scene, ROBOT_ROOT, self._model, meshes, False)
        self._built = True

    def _move_robot(self, snapshot: Snapshot) -> dict[str, Transform]:
        """Move the first robot's links; take them away once it was deleted.

        Returns where its links and extra frames are (none once deleted).
        """
        if snapshot.robot_pose is None:
            robot = self._bodies.pop(ROBOT_ROOT, None)
            if robot is not None:
                robot.remove()
                for folder, _image in self._images.values():  # its cameras' last images
                    folder.remove()
                self._images.clear()
            return {}
        poses = frame_poses(self._model, snapshot.positions, snapshot.robot_pose,
                            self._extra_frames)
        self._bodies[ROBOT_ROOT].move(poses)
        return poses

    @property
    def drawn(self) -> list[str]:
        """The scene roots of the bodies drawn: '/robot' and '/objects/<entity>'."""
        return list(self._bodies)

    def _apply_show_frames(self) -> None:
        for body in self._bodies.values():
            body.show_axes(self._show_frames.value)

    def _move_entities(self, snapshot: Snapshot) -> None:
        scene = self.server.scene
        for name, view in snapshot.entities.items():
            root = f'/objects/{_safe(name)}'
            body = self._bodies.get(root)
            if body is None:
                body = self._add_entity(scene, root, name, view)
                if body is None:
                    continue
            if view.description is None:
                body.move({body.model.root: view.pose})
            else:
                model = view.description.model
                body.move({link: view.pose.then(pose)
                           for link, pose in model.link_poses(view.positions).items()})
        present = {f'/objects/{_safe(name)}' for name in snapshot.entities}
        for root in [root for root in self._bodies if root.startswith('/objects/')]:
            if root not in present:
                self._bodies.pop(root).remove()

    def _add_entity(self, scene: Any, root: str, name: str, view: Any) -> _Body | None:
        if view.description is not None:
            model = view.description.model
            meshes, warnings = robot_visuals(model, view.description.source.parent)
            for warning in warnings:
                self._logger.warning(f"viewer: object '{name}': {warning}")
        else:
            target = next((t for t in TARGET_SET if TARGET_PREFIX + t.name == name), None)
            if target is None:
                return None
            side = 2.0 * target.half_size
            vertices, faces = box_mesh((side, side, side))
            model = RobotModel(name=name, links=(Link(name),), joints=())
            meshes = [VisualMesh(name, 0, vertices, faces, target.rgba)]
        body = _Body(scene, root, model, meshes, bool(self._show_frames.value))
        self._bodies[root] = body
        return body

    # --- sensors --------------------------------------------------------------------------

    def _draw_sensors(self, poses: Mapping[str, Transform]) -> None:
        if not self.taps.watching:
            for handle in self._clouds.values():
                handle.visible = False
            return
        latest = dict(self.taps.latest)
        for entry in self.taps.topics:
            message = latest.get(entry.topic)
            if message is None or self._shown.get(entry.topic) is message:
                continue
            self._shown[entry.topic] = message
            if entry.kind == 'image':
                self._draw_image(entry.name, message)
            else:
                points = scan_points(message) if entry.kind == 'scan' else cloud_points(message)
                self._draw_points(entry.name, points, poses.get(message.header.frame_id))

    def _draw_image(self, name: str, message: Any) -> None:
        pixels = image_pixels(message)
        if pixels is None:
            return
        shown = self._images.get(name)
        if shown is None:
            folder = self.server.gui.add_folder(f'Camera: {name}')
            with folder:
                self._images[name] = (folder, self.server.gui.add_image(
                    pixels, format='jpeg', jpeg_quality=JPEG_QUALITY))
        else:
            shown[1].image = pixels

    def _draw_points(self, name: str, points: np.ndarray, pose: Transform | None) -> None:
        if pose is None:
            return
        handle = self._clouds.get(name)
        if handle is None:
            handle = self.server.scene.add_point_cloud(
                f'/sensors/{_safe(name)}', points, POINT_RGB, point_size=POINT_SIZE,
                precision='float32')
            self._clouds[name] = handle
        else:
            handle.points = points
        handle.position = pose.translation
        handle.wxyz = wxyz(pose)
        handle.visible = True

    # --- the controls ---------------------------------------------------------------------

    def _update_controls(self, snapshot: Snapshot) -> None:
        now = time.monotonic()
        if now - self._status_at >= STATUS_PERIOD_S:
            self._status_at = now
            state = 'paused' if snapshot.paused else 'running'
            pace = ('as fast as possible' if snapshot.real_time_factor == 0.0
                    else f'{snapshot.real_time_factor:g}x real time')
            self._status.content = f'**sim time {snapshot.time:.2f} s**, {state}, {pace}'
            self._pause_button.label = 'Play' if snapshot.paused else 'Pause'
            if self._rate.value != snapshot.real_time_factor:
                self._rate.value = snapshot.real_time_factor
        if snapshot.sliders != self._slider_specs:
            self._build_sliders(snapshot)

    def _build_sliders(self, snapshot: Snapshot) -> None:
        if self._slider_folder is not None:
            self._slider_folder.remove()
        self._sliders = {}
        self._slider_specs = snapshot.sliders
        if not snapshot.sliders:
            self._slider_folder = None
            return
        gui = self.server.gui
        self._slider_folder = gui.add_folder('Joints (position commands)')
        with self._slider_folder:
            for spec in snapshot.sliders:
                handle = gui.add_slider(
                    spec.joint, spec.lower, spec.upper, SLIDER_STEP,
                    spec.clamp(snapshot.positions.get(spec.joint, 0.0)),
                    hint=f'publishes on {spec.channel.topic}')
                handle.on_update(self._slider_moved(spec))
                self._sliders[spec.joint] = handle

    def _slider_moved(self, spec: Slider) -> Any:
        def moved(event: Any) -> None:
            if event.client is None:
                return  # set by the server, not by a user
            self.command(spec, float(event.target.value))
        return moved

    def command(self, spec: Slider, value: float) -> None:
        """Publish the command a slider at ``value`` stands for.

        The other joints of its topic keep their sliders' values.
        """
        channel = spec.channel
        targets = {joint: float(self._sliders[joint].value) for joint in channel.joints
                   if joint in self._sliders}
        targets[spec.joint] = spec.clamp(value)
        positions = self._latest.positions if self._latest is not None else {}
        self.sender.send(channel, command_message(channel, targets, positions, self._model))

    @property
    def sliders(self) -> tuple[Slider, ...]:
        """The joint sliders shown now (built with the scene, when a browser first connects)."""
        return self._slider_specs

    def pause(self, paused: bool) -> None:
        """Hold or release the physics, as the pause/play button does."""
        self.access.call(lambda: self._node.set_paused(paused))

    def reset(self) -> None:
        """Put the world back to its start, as the reset button does (sim_node's reset)."""
        self.access.call(self._node.reset)

    def set_real_time_factor(self, value: float) -> None:
        """Set sim_node's ``real_time_factor`` parameter, as the control does."""
        self.access.call(lambda: self._node.set_parameters(
            [Parameter('real_time_factor', value=float(value))]))

    def _set_rate(self, event: Any) -> None:
        if event.client is not None:  # else set by the server, following the node
            self.set_real_time_factor(event.target.value)

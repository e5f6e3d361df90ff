"""Gazebo's model interface, as gazebo_ros_api_plugin offers it, served from the simulation.

Topics /gazebo/model_states and /gazebo/link_states (every physics step,
while someone subscribes) and /gazebo/set_model_state; services
get/set_model_state, spawn_urdf_model, spawn_sdf_model, delete_model,
get_world_properties, get_model_properties, get/set_physics_properties.
A request that cannot be met gets success false and a status_message that
says why; nothing is changed then.

Every change to the world runs in the step loop's thread, between steps
(loop.Requests): pybullet is not to be called from two threads, and a
spawned robot's topics join the step loop's publishing. It is handed what it serves from, not the node:
the simulation, the step loop's requests, the fleet of robot interfaces,
the world's markers and the pacer.
"""
import math

import rospy
from gazebo_msgs.msg import LinkStates, ModelState, ModelStates, ODEPhysics
from gazebo_msgs.srv import (
    DeleteModel,
    DeleteModelResponse,
    GetModelProperties,
    GetModelPropertiesResponse,
    GetModelState,
    GetModelStateResponse,
    GetPhysicsProperties,
    GetPhysicsPropertiesResponse,
    GetWorldProperties,
    GetWorldPropertiesResponse,
    SetModelState,
    SetModelStateResponse,
    SetPhysicsProperties,
    SetPhysicsPropertiesResponse,
    SpawnModel,
    SpawnModelResponse,
)
from geometry_msgs.msg import Pose, Twist

from ..frames import compose, normalized
from ..model_files import ModelFileError, check_urdf, link_shapes, parse_sdf
from ..robot_model import ModelError, load_model_text
from ..simulation import ModelStateError
from . import messages

#: What GetPhysicsProperties reports as ode_config: Gazebo's own defaults (pybullet uses none of them).
ODE_DEFAULTS = dict(auto_disable_bodies=False, sor_pgs_precon_iters=0, sor_pgs_iters=50, sor_pgs_w=1.3,
                    sor_pgs_rms_error_tol=0.0, contact_surface_layer=0.001, contact_max_correcting_vel=100.0,
                    cfm=0.0, erp=0.2, max_contacts=20)


def _pose(message):
    return ((message.position.x, message.position.y, message.position.z),
            (message.orientation.x, message.orientation.y, message.orientation.z, message.orientation.w))


def _vector(message):
    return (message.x, message.y, message.z)


def _fill_pose(message, pose):
    (message.position.x, message.position.y, message.position.z), orientation = pose
    message.orientation.x, message.orientation.y, message.orientation.z, message.orientation.w = orientation
    return message


def _fill_twist(message, linear, angular):
    message.linear.x, message.linear.y, message.linear.z = linear
    message.angular.x, message.angular.y, message.angular.z = angular
    return message


def _finite(*values):
    return all(math.isfinite(value) for value in values)


class GazeboInterface(object):

    def __init__(self, sim, publishers, requests, fleet, markers, pacer, warn):
        """`warn(kind, text)`: a throttled warning."""
        self.sim, self.requests, self.fleet, self.markers, self.pacer = sim, requests, fleet, markers, pacer
        self._warn = warn
        self.model_states = publishers.advertise('gazebo/model_states', ModelStates)
        self.link_states = publishers.advertise('gazebo/link_states', LinkStates)
        self.set_model_state = rospy.Subscriber('gazebo/set_model_state', ModelState, self._on_set_model_state,
                                                queue_size=10)
        for name, kind, handler in (
                ('get_model_state', GetModelState, self._get_model_state),
                ('set_model_state', SetModelState, self._set_model_state),
                ('spawn_urdf_model', SpawnModel, self._spawn_urdf_model),
                ('spawn_sdf_model', SpawnModel, self._spawn_sdf_model),
                ('delete_model', DeleteModel, self._delete_model),
                ('get_world_properties', GetWorldProperties, self._get_world_properties),
                ('get_model_properties', GetModelProperties, self._get_model_properties),
                ('get_physics_properties', GetPhysicsProperties, self._get_physics_properties),
                ('set_physics_properties', SetPhysicsProperties, self._set_physics_properties)):
            rospy.Service('gazebo/' + name, kind, handler)

    # --- every step --------------------------------------------------------------
    def publish(self):
        """The states of every model and link, if someone listens (Gazebo: every update)."""
        if self.model_states.get_num_connections():
            message = ModelStates()
            for name in self.sim.model_names():
                pose, linear, angular = self.sim.model_state(name)
                message.name.append(name)
                message.pose.append(_fill_pose(Pose(), pose))
                message.twist.append(_fill_twist(Twist(), linear, angular))
            self.model_states.publish(message)
        if self.link_states.get_num_connections():
            message = LinkStates()
            for name in self.sim.model_names():
                body = self.sim.model(name)
                for link in (body.link_names if body is not None else ['link']):
                    pose = self.sim.model_state(name)[0] if body is None else body.link_pose(link)
                    message.name.append('%s::%s' % (name, link))
                    message.pose.append(_fill_pose(Pose(), pose))
                    message.twist.append(Twist())
            self.link_states.publish(message)

    # --- requests, each answered in the step loop ----------------------------------
    def _answer(self, response, work, request=None):
        """`response` with success and status_message, after `work()` in the step loop."""
        try:
            status = self.requests.run(work, message=request)
            response.success, response.status_message = True, status or ''
        except (ModelStateError, ModelFileError, ModelError, ValueError) as error:
            response.success, response.status_message = False, str(error)
            self._warn('gazebo request', 'gazebo: %s' % error)
        return response

    def _get_model_state(self, request):
        response = GetModelStateResponse()

        def work():
            pose, linear, angular = self.sim.model_state(request.model_name, request.relative_entity_name)
            _fill_pose(response.pose, pose)
            _fill_twist(response.twist, linear, angular)
            response.header.stamp = messages.stamp_of(self.sim.now_ns)
            response.header.frame_id = request.relative_entity_name
            return 'GetModelState: got properties'
        return self._answer(response, work, request)

    def _set(self, state):
        pose, twist = _pose(state.pose), state.twist
        self.sim.set_model_state(state.model_name, pose, _vector(twist.linear), _vector(twist.angular),
                                 state.reference_frame)
        self.markers.changed()
        return 'SetModelState: set model state done'

    def _set_model_state(self, request):
        return self._answer(SetModelStateResponse(), lambda: self._set(request.model_state), request)

    def _on_set_model_state(self, state):
        try:
            self.requests.run(lambda: self._set(state), message=state)
        except (ModelStateError, ValueError) as error:
            self._warn('gazebo set_model_state topic', 'gazebo/set_model_state: %s' % error)

    def _spawn_pose(self, request):
        """A spawn request's initial_pose in the world (a zero quaternion: no rotation, as Gazebo reads it)."""
        position, orientation = _pose(request.initial_pose)
        if not request.model_name:
            raise ModelStateError('a model needs a name')
        if not _finite(*(position + orientation)):
            raise ModelStateError('model %s: non-finite number in initial_pose %s'
                                  % (request.model_name, position + orientation))
        orientation = (0.0, 0.0, 0.0, 1.0) if not any(orientation) else normalized(orientation)
        return compose(self.sim.frame(request.reference_frame)[0], (position, orientation))

    def _spawn_urdf_model(self, request):
        def work():
            pose = self._spawn_pose(request)
            urdf = check_urdf(request.model_xml)
            namespace = request.robot_namespace.strip('/')
            if namespace:  # a TurtleBot3 (it drives: wheels and limits) becomes a robot with its topics
                model = load_model_text(request.model_xml, request.model_name)
                self.fleet.spawn(namespace, model, pose, request.model_name)
                return 'SpawnModel: robot %s spawned with the topics of namespace /%s' % (request.model_name, namespace)
            self.sim.spawn_object(request.model_name, None, pose, urdf.static, urdf=request.model_xml)
            self.markers.changed()
            return 'SpawnModel: successfully spawned model %s' % request.model_name
        return self._answer(SpawnModelResponse(), work, request)

    def _spawn_sdf_model(self, request):
        def work():
            model = parse_sdf(request.model_xml)
            pose = compose(self._spawn_pose(request), model.pose)
            if model.static:  # one body of every link's shapes, in the model's frame
                shapes = [(shape, visual) for _, shape, visual in link_shapes(model)]
                self.sim.spawn_object(request.model_name, shapes, pose, True)
            else:  # one link (parse_sdf sees to it): the body's base is that link
                (link,) = model.links
                shapes = [(shape, False) for shape in link.collisions] + [(shape, True) for shape in link.visuals]
                self.sim.spawn_object(request.model_name, shapes, pose, False, link.mass, frame_offset=link.pose)
            self.markers.changed()
            return 'SpawnModel: successfully spawned model %s' % request.model_name
        return self._answer(SpawnModelResponse(), work, request)

    def _delete_model(self, request):
        def work():
            robot = self.sim.delete_model(request.model_name)
            if robot is not None:
                self.fleet.forget(robot)
            self.markers.changed()
            return 'DeleteModel: successfully deleted model %s' % request.model_name
        return self._answer(DeleteModelResponse(), work, request)

    def _get_world_properties(self, request):
        response = GetWorldPropertiesResponse()

        def work():
            response.sim_time = self.sim.now_ns * 1e-9
            response.model_names = self.sim.model_names()
            response.rendering_enabled = bool(self.sim.config.gui)
            return 'GetWorldProperties: got properties'
        return self._answer(response, work, request)

    def _get_model_properties(self, request):
        response = GetModelPropertiesResponse()

        def work():
            body = self.sim.model(request.model_name)
            name = request.model_name
            if body is None:
                response.canonical_body_name, response.body_names = name + '::link', [name + '::link']
                response.is_static = True
                return 'GetModelProperties: got properties'
            response.body_names = ['%s::%s' % (name, link) for link in body.link_names]
            response.canonical_body_name = response.body_names[0]
            response.joint_names = list(body.joint_names)
            response.is_static = body.static
            return 'GetModelProperties: got properties'
        return self._answer(response, work, request)

    def _get_physics_properties(self, request):
        response = GetPhysicsPropertiesResponse()

        def work():
            step = self.sim.step_ns * 1e-9
            factor = self.pacer.factor
            response.time_step, response.pause = step, self.pacer.paused
            response.max_update_rate = factor / step
            response.gravity.x, response.gravity.y, response.gravity.z = self.sim.world.gravity
            response.ode_config = ODEPhysics(**ODE_DEFAULTS)
            return ('GetPhysicsProperties: pybullet steps at time_step; max_update_rate / (1 / time_step) is the '
                    'real-time factor (0: as fast as possible); ode_config is Gazebo\'s default, unused here')
        return self._answer(response, work, request)

    def _set_physics_properties(self, request):
        def work():
            step, rate = request.time_step, request.max_update_rate
            gravity = _vector(request.gravity)
            if not _finite(step, rate, *gravity) or not step > 0.0 or rate < 0.0:
                raise ModelStateError('time_step %r must be > 0, max_update_rate %r >= 0, gravity %s finite'
                                      % (step, rate, gravity))
            slowest = self.fleet.fastest_output()
            if 1.0 / step < slowest[1]:
                raise ModelStateError('time_step %g s gives %g physics steps per second, fewer than ~%s (%g Hz)'
                                      % (step, 1.0 / step, slowest[0], slowest[1]))
            self.sim.set_time_step(step)
            self.sim.world.set_gravity(gravity)
            self.pacer.set_factor(rate * step)
            rospy.loginfo('set_physics_properties: time step %g s, real-time factor %g (0: as fast as possible), '
                          'gravity %s', step, rate * step, gravity)
            return 'SetPhysicsProperties: done (ode_config is not used here)'
        return self._answer(SetPhysicsPropertiesResponse(), work, request)

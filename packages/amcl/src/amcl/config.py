"""amcl's parameters as this node reads them, and which of them are live. No ROS here.

Every parameter amcl's node reads (ros-planning/navigation noetic,
amcl/src/amcl_node.cpp) is taken here, so that a launch file written for
amcl runs unchanged:

- the filter's (particles, laser and odometry models, frames) are
  tb3_navigation.amcl_config.AmclConfig's, honoured there;
- the node's own (where the map comes from, saving the pose, forced
  updates) are AmclNodeConfig's below, honoured by the node;
- UNHONOURED names the rest with why; the node says so at start for those
  set to a value other than their HARMLESS one.

LIVE names AMCL.cfg's parameters this node serves through
dynamic_reconfigure at `/amcl` (cfg/AMCL.cfg makes the server's type from
the configs' fields: one source).
"""
import dataclasses

from tb3_common.params import Checked, number, parameter
from tb3_navigation.amcl_config import AmclConfig
from tb3_navigation.localization import Amcl

#: AMCL.cfg's parameters that AmclConfig has: a change reaches the filter at its next update.
LIVE = ('min_particles', 'max_particles', 'kld_err', 'kld_z', 'update_min_d', 'update_min_a', 'resample_interval',
        'transform_tolerance', 'recovery_alpha_slow', 'recovery_alpha_fast', 'tf_broadcast', 'gui_publish_rate',
        'laser_min_range', 'laser_max_range', 'laser_max_beams', 'laser_z_hit', 'laser_z_short', 'laser_z_max',
        'laser_z_rand', 'laser_sigma_hit', 'laser_lambda_short', 'laser_likelihood_max_dist', 'laser_model_type',
        'odom_model_type', 'odom_alpha1', 'odom_alpha2', 'odom_alpha3', 'odom_alpha4', 'odom_frame_id',
        'base_frame_id', 'global_frame_id')
#: AmclConfig's parameters the filter builds its laser model from: changing one makes the filter anew
#: around its estimate, as amcl makes it anew on every change; the others are read at each update.
MODEL = ('laser_z_hit', 'laser_z_rand', 'laser_sigma_hit', 'laser_likelihood_max_dist', 'laser_model_type')

_BEAMSKIP = 'no beam skipping here: every beam of laser_max_beams is weighed'
_STD_WARN = "no warning on the estimate's spread here"
UNHONOURED = {
    'do_beamskip': _BEAMSKIP, 'beam_skip_distance': _BEAMSKIP, 'beam_skip_threshold': _BEAMSKIP,
    'beam_skip_error_threshold': _BEAMSKIP,
    'odom_alpha5': "only amcl's omni models use it; a TurtleBot3 is differential (diff or diff-corrected)",
    'selective_resampling': 'the filter resamples every resample_interval updates here',
    'bag_scan_period': 'amcl reads it only when it plays a bag itself; this node never does',
    'std_warn_level_x': _STD_WARN, 'std_warn_level_y': _STD_WARN, 'std_warn_level_yaw': _STD_WARN,
}
HARMLESS = {'do_beamskip': False, 'selective_resampling': False}


@dataclasses.dataclass(frozen=True)
class AmclNodeConfig(Checked):
    """amcl's node parameters (not the filter's), amcl's defaults; `live` ones are AMCL.cfg's too."""
    use_map_topic: bool = parameter(False, 'the map from the `map` topic, not the static_map service')
    first_map_only: bool = parameter(False, 'with use_map_topic: later maps on the topic are ignored')
    save_pose_rate: float = parameter(0.5, 'Hz: the pose is saved to ~initial_pose_* and ~initial_cov_* this often '
                                           '(a restarted amcl resumes there); <= 0: never', None, 'Hz', live=True)
    force_update_after_initialpose: bool = parameter(False, 'an initial pose updates the filter with the next scan, '
                                                            'moved or not', live=True)
    force_update_after_set_map: bool = parameter(False, 'so does a map from set_map', live=True)
    seed: int = parameter(-1, 'ours: the particles\' random numbers; -1: random, a number makes runs repeatable',
                          number(-1))


def amcl_values(tree, frames):
    """{field: value} of AmclConfig from the node's private parameters `tree` (a dict, as rospy's
    get_param('~') gives it): each value set, else `frames` {odom_frame_id...: the robot's frame}, else
    the field's default."""
    return dict((field.name, tree.get(field.name, frames.get(field.name, field.default)))
                for field in dataclasses.fields(AmclConfig))


def node_values(tree):
    """{field: value} of AmclNodeConfig from `tree`."""
    return dict((field.name, tree.get(field.name, field.default)) for field in dataclasses.fields(AmclNodeConfig))


def unhonoured(tree):
    """{name: why} of the UNHONOURED parameters set in `tree` to a value other than their harmless one."""
    return dict((name, why) for name, why in UNHONOURED.items()
                if name in tree and not (name in HARMLESS and tree[name] == HARMLESS[name]))


def live_fields():
    """[(config class, field)] of the parameters /amcl serves live, in AMCL.cfg's order."""
    filter_fields = dict((field.name, field) for field in dataclasses.fields(AmclConfig))
    return ([(AmclConfig, filter_fields[name]) for name in LIVE] +
            [(AmclNodeConfig, field) for field in dataclasses.fields(AmclNodeConfig) if field.metadata.get('live')])


def changed(config, node_config, values):
    """(AmclConfig, AmclNodeConfig, the changes {name: value}, whether the laser model changed) once
    dynamic_reconfigure's `values` {name: value} are taken; ParameterError, and nothing taken, if one is bad."""
    names = dict((field.name, cls) for cls, field in live_fields())
    current = {AmclConfig: config, AmclNodeConfig: node_config}
    changes = dict((name, value) for name, value in values.items()
                   if name in names and value != getattr(current[names[name]], name))
    for cls in current:
        ours = dict((name, value) for name, value in changes.items() if names[name] is cls)
        if ours:
            current[cls] = current[cls].replace(**ours)
    return current[AmclConfig], current[AmclNodeConfig], changes, any(name in MODEL for name in changes)


def reconfigured(amcl, config, model, grid, values, seed=None):
    """The filter (a tb3_navigation.localization.Amcl on the map `grid`, `values`) that takes `config`:
    the same one reading it from its next update on, or, when the laser `model` changed, one made anew
    with max_particles around the estimate and its covariance, as amcl's reconfigureCB makes it."""
    if not model:
        amcl.config = config
        return amcl
    estimate = amcl.estimate()
    fresh = Amcl(config, grid, values, seed)
    fresh.initialise(estimate.pose, estimate.covariance)
    return fresh

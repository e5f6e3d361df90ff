"""The pure half of `make demo`: recorded paths in, table text and PNG out.

No rospy here: a path is a list of (stamp_s, x_m, y_m, yaw_rad) samples, a run
a `RunResult`; `summarize` turns a run into end poses and errors, `table`
into text, `plot_paths` into a picture (matplotlib, Agg backend).

`figure` prints a measured number as a line that tools/repeat.py gathers
across runs of a test (`map_figures`: those of a map that a bound judges).
"""
import math
from collections import namedtuple

from tb3_common.pose2d import normalize_angle

RunResult = namedtuple('RunResult', 'script truth odom wall_time sim_time exit_code error')
RunResult.__doc__ = """One script's run.

truth, odom: paths from base_pose_ground_truth and odom, from the script's start
wall_time, sim_time: seconds from `rosrun` to the script's exit
exit_code: the script's, or None if it never ran or was stopped
error: None, or what went wrong (text)
"""

Summary = namedtuple('Summary', 'start end odom_end error_distance error_heading '
                                'drift_distance drift_heading travelled turned')


def nearest(path, stamp):
    """The sample of `path` whose stamp is closest to `stamp`."""
    return min(path, key=lambda sample: abs(sample[0] - stamp))


def summarize(run):
    """End pose and errors of a run, or None without ground truth."""
    if not run.truth:
        return None
    start, end = run.truth[0], run.truth[-1]
    travelled = turned = 0.0
    for before, after in zip(run.truth, run.truth[1:]):
        travelled += math.hypot(after[1] - before[1], after[2] - before[2])
        turned += abs(normalize_angle(after[3] - before[3]))
    odom_end = drift_distance = drift_heading = None
    if run.odom:
        odom_end = run.odom[-1]
        truth_then = nearest(run.truth, odom_end[0])
        drift_distance = math.hypot(odom_end[1] - truth_then[1], odom_end[2] - truth_then[2])
        drift_heading = normalize_angle(odom_end[3] - truth_then[3])
    return Summary(start, end, odom_end,
                   math.hypot(end[1] - start[1], end[2] - start[2]), normalize_angle(end[3] - start[3]),
                   drift_distance, drift_heading, travelled, turned)


def _pose(sample):
    return 'x %+7.3f m   y %+7.3f m   yaw %+7.2f deg' % (sample[1], sample[2], math.degrees(sample[3]))


def table(run):
    """The lines of one run's table."""
    status = 'exit %s' % run.exit_code if run.error is None else 'FAILED: %s' % run.error
    lines = ['== %s  (%s)' % (run.script, status)]
    if run.wall_time is not None:
        lines.append('  wall time            %8.1f s' % run.wall_time)
    if run.sim_time is not None:
        lines.append('  sim time             %8.1f s' % run.sim_time)
    summary = summarize(run)
    if summary is None:
        lines.append('  (no ground truth recorded)')
        return lines
    lines += [
        '  ground truth start   ' + _pose(summary.start),
        '  ground truth end     ' + _pose(summary.end),
        '  error from start     %8.3f m   heading %+7.2f deg'
        % (summary.error_distance, math.degrees(summary.error_heading)),
        '  travelled            %8.3f m   turned  %7.1f deg'
        % (summary.travelled, math.degrees(summary.turned)),
    ]
    if summary.odom_end is None:
        lines.append('  (no odometry recorded)')
    else:
        lines += [
            '  odometry end         ' + _pose(summary.odom_end),
            '  odometry drift       %8.3f m   heading %+7.2f deg  (odom - ground truth)'
            % (summary.drift_distance, math.degrees(summary.drift_heading)),
        ]
    return lines


def figure(name, value, worse='max', unit=''):
    """Prints `FIGURE <name> <value> <worse> [<unit>]`: a number a bound judges, where
    `worse` says which way is worse ('max': larger, 'min': smaller)."""
    if worse not in ('max', 'min') or not name or any(c.isspace() for c in name + unit):
        raise ValueError('figure(%r, %r, %r, %r): a name and unit without spaces, worse max or min'
                         % (name, value, worse, unit))
    print(' '.join(['FIGURE', name, '%.6g' % value, worse, unit]).rstrip(), flush=True)


def map_figures(prefix, quality):
    """The figures of a map_quality.MapQuality that its goals judge, named `prefix`_<measure>."""
    figure(prefix + '_occupied_near_surface', 100 * quality.occupied_near_surface, 'min', '%')
    figure(prefix + '_surface_covered', 100 * quality.surface_covered, 'min', '%')
    figure(prefix + '_wall_thickness', quality.wall_thickness, 'max', 'cells')


def plot_paths(runs, filename, title):
    """One panel per run: ground truth and odometry in the odom frame (m)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, len(runs), figsize=(5.2 * len(runs), 5.6), squeeze=False)
    for axis, run in zip(axes[0], runs):
        summary = summarize(run)
        axis.set_aspect('equal', adjustable='datalim')
        axis.grid(True, color='0.85')
        axis.set_xlabel('x (m)')
        axis.set_ylabel('y (m)')
        if summary is None:
            axis.set_title('%s\nno data (%s)' % (run.script, run.error or 'no ground truth'), fontsize=11)
            continue
        for path, style, label in ((run.truth, dict(color='tab:blue', lw=2.5, alpha=0.8), 'ground truth'),
                                   (run.odom, dict(color='tab:orange', lw=1.2, ls='--'), 'odometry')):
            if path:
                axis.plot([s[1] for s in path], [s[2] for s in path], label=label, **style)
        start, end = summary.start, summary.end
        axis.plot(start[1], start[2], 'o', color='tab:green', ms=10, label='start', zorder=3)
        axis.plot(end[1], end[2], 's', color='tab:red', ms=7, label='end', zorder=4)
        arrow = 0.15  # m: heading arrows at start and end
        for sample, color in ((start, 'tab:green'), (end, 'tab:red')):
            axis.annotate('', xy=(sample[1] + arrow * math.cos(sample[3]), sample[2] + arrow * math.sin(sample[3])),
                          xytext=(sample[1], sample[2]),
                          arrowprops=dict(arrowstyle='->', color=color, lw=1.5), zorder=5)
        status = '' if run.error is None else '  FAILED'
        axis.set_title('%s%s\nend error %.3f m, %+.1f deg (sim %.0f s)'
                       % (run.script, status, summary.error_distance,
                          math.degrees(summary.error_heading), run.sim_time or 0.0), fontsize=11)
        xs = [s[1] for s in run.truth + run.odom]
        ys = [s[2] for s in run.truth + run.odom]
        margin = 0.25
        axis.set_xlim(min(xs) - margin, max(xs) + margin)
        axis.set_ylim(min(ys) - margin, max(ys) + margin)
        axis.legend(loc='best', fontsize=8, framealpha=0.9)
        if summary.odom_end is not None:
            axis.text(0.98, 0.02, 'odometry drift at the end: %.3f m, %+.1f deg'
                      % (summary.drift_distance, math.degrees(summary.drift_heading)),
                      transform=axis.transAxes, ha='right', va='bottom', fontsize=8,
                      bbox=dict(facecolor='white', edgecolor='0.8', alpha=0.9))
    figure.suptitle(title, fontsize=12)
    figure.tight_layout()
    figure.savefig(filename, dpi=100)
    plt.close(figure)

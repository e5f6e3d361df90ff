"""A world's rays: those of every lidar of a step, met in numpy where it can and by pybullet where it must.

Rays meet the ground and every body of boxes, cylinders and spheres (the
obstacles, the robots where their links are now, spawned models) in numpy
(rays.py), all lidars of a step at once; only the rays that pass near a body
with another shape (a robot's mesh) are cast by pybullet.

world.World holds one WorldRays (its `rays`) and tells it when a static body
came, went or moved; world.py keeps to building, stepping and rendering.
"""
import math

import numpy as np

from .bodies import int32
from .frames import compose
from .rays import Scene

STATIC_BODIES = 2        # Bullet's collision group of bodies with mass 0
#: Still shapes within a lidar's reach past which pybullet casts all its rays
#: instead of numpy: numpy tested every beam against every shape near it, and a
#: map world's walls (670 boxes in rbx1's test map) made a scan 25 times
#: turtlebot3_world's (15 shapes). Since rays.py culls by heading, numpy casts
#: that map (270-280 within reach) at 0.70-0.83 ms a scan, pybullet at 1.55-1.88
#: (2026-11-24): the bound could rise, changing such ranges by Bullet's margins.
MAX_STILL_SHAPES = 40


class WorldRays(object):
    """The rays of a world.World (its client `p`, its `objects` and `robots`), and the Scenes they are met in."""

    def __init__(self, world):
        self.world = world
        self._still = None  # the Scene of the still world, made anew when a static object comes, goes or moves
        self._moving = None  # the bodies not in it, and the Scene of their shapes in their links' frames

    def moved(self, body):
        """`body` came, went or was teleported: a static one changes what the rays meet."""
        if body.static:
            self._still = None

    def _still_scene(self):
        """The rays' Scene of the still world: every shape of the static objects built of shapes."""
        if self._still is None:
            self._still = Scene([(kind, size, compose(body.base_pose(), pose))
                                 for body in self.world.objects.values() if body.static and body.shapes
                                 for kind, size, pose in body.shapes])
        return self._still

    def _moving_scene(self):
        """(scene, shaped, others) of the bodies not in the still Scene: `shaped`, those
        of boxes, cylinders and spheres, whose shapes `scene` holds in their links'
        frames, each owned by its body's index in `shaped`; `others`, the bodies that
        pybullet must meet (a mesh). Made anew when a body comes or goes."""
        world = self.world
        bodies = [body for body in world.robots + list(world.objects.values()) if not (body.static and body.shapes)]
        if self._moving is None or self._moving[0] != bodies:
            shaped = [body for body in bodies if body.collisions is not None]
            scene = Scene([(kind, size, pose) for body in shaped for _, kind, size, pose in body.collisions],
                          [owner for owner, body in enumerate(shaped) for _ in body.collisions])
            self._moving = (bodies, scene, shaped, [body for body in bodies if body.collisions is None])
        return self._moving[1:]

    def cast(self, origins, directions, length, ignore):
        """Distance (L x N, m) along each of N rays from each of L origins (L x 3)
        in the unit `directions` (L x N x 3) to the first surface within `length`,
        inf where none; origin l's rays pass through the robot body ignore[l].

        The ground and every body of boxes, cylinders and spheres are met in
        numpy (rays.py), all rays at once, the moving ones where their links
        are now; pybullet casts only the rays that pass within the bounding
        sphere of a body with another shape (a mesh), each origin's together.
        """
        origins, directions = np.asarray(origins, dtype=float), np.asarray(directions, dtype=float)
        still = self._still_scene()
        crowded = still.reachable(origins, length) > MAX_STILL_SHAPES
        local, shaped, others = self._moving_scene()
        distances = np.full(directions.shape[:2], math.inf)
        if not crowded.all():
            frames = [frame for body in shaped for frame in body.collision_frames()]
            scene = still + local.placed([position for position, _ in frames], [turn for _, turn in frames])
            owners = np.array([shaped.index(body) if body in shaped else -2 for body in ignore])  # -2: nobody's
            distances[~crowded] = scene.cast(origins[~crowded], directions[~crowded], length, owners[~crowded])
        # pybullet then tests the others only: the still shapes (group 2, with
        # the ground) are met already, unless a static body is among the others.
        met = STATIC_BODIES if not any(body.static for body in others) else 0
        for index, (origin, own) in enumerate(zip(origins, ignore)):
            reach = np.zeros(directions.shape[1])  # how far each ray must go to pass the bodies it nears
            mask = 0xFFFFFFFF & ~(own.group if own is not None else 0)
            if crowded[index]:  # every ray, to its full length, whatever it meets
                reach[:] = length
            else:
                mask &= ~met
                for body in others:
                    if body is not own:
                        reach = np.maximum(reach, _passing(origin, directions[index], length, body))
            near = reach > 0.0
            if near.any():
                reach = reach[near]
                ends = origin + directions[index, near] * reach[:, None]
                hits = self.world.p.rayTestBatch(np.broadcast_to(origin, ends.shape), ends, numThreads=1,
                                           collisionFilterMask=int32(mask))
                found = np.array([hit[2] if hit[0] >= 0 else math.inf for hit in hits]) * reach
                distances[index, near] = np.minimum(distances[index, near], found)
        return distances


def _passing(origin, directions, length, body):
    """Per ray, how far it must go (at most `length`) to pass `body`'s bounding
    sphere; 0 for a ray that never comes within it."""
    offset = np.asarray(body.centre()) - origin
    along = directions.dot(offset)
    across = offset.dot(offset) - along * along
    meets = (across <= body.radius ** 2) & (along >= -body.radius) & (along - body.radius <= length)
    return np.where(meets, np.minimum(along + body.radius, length), 0.0)

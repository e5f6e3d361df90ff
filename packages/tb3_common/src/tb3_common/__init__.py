"""The shared pieces of the simulator and the navigation nodes: poses, grids, map files (no ROS).

One BLAS thread for the process that imports it first, before numpy: numpy's
OpenBLAS otherwise starts a thread per core that spins (sched_yield) between
small products, taking the other nodes' and the simulator's core (amcl at
factor 1: a core's 31 % with it, 6 % without; the DQN agent's learning step
7.1 ms of CPU with it, 3.5 ms without: doc/speed.md). The node packages
import this package first; a program that imported numpy before keeps its
own setting, and a value in the environment wins.
"""
import os

for _variable in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_variable, '1')

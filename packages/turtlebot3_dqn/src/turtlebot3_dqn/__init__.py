"""ROBOTIS' turtlebot3_dqn (the e-manual's machine-learning chapter) on Python 3 and PyTorch.

One BLAS thread: numpy's OpenBLAS otherwise starts a thread per core that
spins between the network's small products, taking the simulator's core: a
learning step cost 7.1 ms of CPU with it and 3.5 ms without (see
doc/speed.md). Set here, before numpy is first imported by the nodes (a
program that imported numpy before this package keeps its own setting).
"""
import os

for _variable in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_variable, '1')

"""ROBOTIS' turtlebot3_dqn (the e-manual's machine-learning chapter) on Python 3 and PyTorch.

One BLAS thread (tb3_common's docstring), set before numpy is first imported by the nodes.
"""
import tb3_common  # noqa: F401 (first, before numpy)

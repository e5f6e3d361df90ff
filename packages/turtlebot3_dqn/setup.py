# Used by catkin_python_setup() only; do not run it by hand.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=['turtlebot3_dqn'],
    package_dir={'': 'src'},
))

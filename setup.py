# Used by catkin_python_setup() only; do not run it by hand.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    # transform_utils is a package, not a py_module: catkin's devel-space
    # relays get the folder of a py_module under package_dir wrong.
    packages=['tb3_sim_nav', 'tb3_sim_nav.ros', 'rbx1_nav', 'transform_utils'],
    package_dir={'': 'src'},
))

# The Python package sowing_robot (python/sowing_robot), installed by catkin_python_setup(); the
# compiled sowing_robot.core and the generated sowing_robot.msg / .cfg join it in devel and install.
from setuptools import setup

from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["sowing_robot", "sowing_robot.analyze_bag"],
                                 package_dir={"": "python"}))

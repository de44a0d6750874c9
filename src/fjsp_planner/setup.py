from glob import glob

from setuptools import find_packages, setup

package_name = 'fjsp_planner'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    package_data={'fjsp_planner.observe': ['web/*']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/scenarios', glob('../../config/scenarios/*.yaml')),
        ('share/' + package_name + '/params', glob('../../config/params/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='fjsp team',
    maintainer_email='team@fjsp.invalid',
    description='Multi-robot assembly task allocation: CP-SAT planner and ROS 2 nodes',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'fjsp-solve = fjsp_planner.cli:main',
            'planner_node = fjsp_planner.nodes.planner:main',
            'monitor_node = fjsp_planner.nodes.monitor:main',
            'recorder = fjsp_planner.nodes.recorder:main',
            'replay = fjsp_planner.observe.replay:run',
            'inject_fault = fjsp_planner.faults:main',
            'mission = fjsp_planner.missions:main',
            'fleet = fjsp_planner.launcher.cli:main',
        ],
    },
)

from setuptools import find_packages, setup

package_name = 'robot_agents'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='fjsp team',
    maintainer_email='team@fjsp.invalid',
    description='Generic robot agent executing planned task sequences through a driver '
                '(+ per-type aliases), and a simulated robot serving its actions',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'robot_agent = robot_agents.agent_node:main',
            'assembler_agent = robot_agents.agent_node:assembler_main',
            'marc_agent = robot_agents.agent_node:marc_main',
            'lsms_agent = robot_agents.agent_node:lsms_main',
            'sim_robot = robot_agents.sim_robot:main',
        ],
    },
)

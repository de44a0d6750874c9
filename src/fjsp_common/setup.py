from setuptools import find_packages, setup

package_name = 'fjsp_common'

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
    description='The fleet contract shared by the planner, the agents and the monitor',
    license='Apache-2.0',
)

"""`ros2 run` and `ros2 pkg executables`: executables found through the ament index exactly
as ros2cli finds them, so the packages stay standard ament packages and a real `ros2` works
on them unchanged."""

import os
import sys

from ament_index_python.packages import (
    PackageNotFoundError,
    get_package_prefix,
    get_packages_with_prefixes,
)

from .graph import CommandError

RUN_USAGE = 'usage: ros2 run <package> <executable> [args] [--ros-args ...]'


def executables(prefix: str, package: str) -> list[str]:
    directory = os.path.join(prefix, 'lib', package)
    if not os.path.isdir(directory):
        return []
    return sorted(name for name in os.listdir(directory)
                  if os.path.isfile(os.path.join(directory, name))
                  and os.access(os.path.join(directory, name), os.X_OK))


def package_prefix(package: str) -> str:
    try:
        return get_package_prefix(package)
    except (PackageNotFoundError, LookupError, ValueError):
        raise CommandError(f"Package '{package}' not found") from None


def run(argv) -> int:
    if len(argv) < 2 or argv[0] in ('-h', '--help'):
        print(RUN_USAGE, file=sys.stdout if argv[:1] in (['-h'], ['--help']) else sys.stderr)
        return 0 if argv[:1] in (['-h'], ['--help']) else 2
    package, executable, rest = argv[0], argv[1], argv[2:]
    prefix = package_prefix(package)
    if executable not in executables(prefix, package):
        raise CommandError(f"No executable found: '{executable}' is not one of package "
                           f"'{package}' (see `ros2 pkg executables {package}`)")
    path = os.path.join(prefix, 'lib', package, executable)
    sys.stdout.flush()
    # Replace this process, as ros2cli's run does, so signals reach the node directly.
    os.execv(path, [path, *rest])


def pkg(argv) -> int:
    if argv[:1] != ['executables'] or len(argv) > 2:
        raise CommandError('only `ros2 pkg executables [package]` is provided')
    packages = ({argv[1]: package_prefix(argv[1])} if len(argv) == 2
                else get_packages_with_prefixes())
    for package in sorted(packages):
        for name in executables(packages[package], package):
            print(f'{package} {name}')
    return 0

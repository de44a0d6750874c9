"""Separate hosts on one Linux machine, for testing a fleet across real network links: each
host is a network namespace with an interface of its own (a veth pair) plugged into one
bridge, the LAN, whose other side is this machine's own network namespace.

Loopback hides what a real network does to a fleet: a link that goes down and comes back,
discovery that must cross it, messages held up and delivered in a burst. Here each node can
run on a host of its own (`Host.prefix`: `ip netns exec <namespace>`), and a host's link can
be cut and restored (`Network.cut`, `Network.restore`) as if its cable were pulled at the
switch: the host keeps running, alone.

Creating namespaces needs root (CAP_SYS_ADMIN and CAP_NET_ADMIN) and iproute2's `ip`;
`Network()` raises `HostsUnavailableError` saying why when it cannot. Every run claims a LAN
number with a lock file (as test ROS domains are claimed), which names its namespaces,
interfaces and subnet (`10.213.<n>.0/24`), so runs at once never collide; `close()` removes
all of it, and what a killed run left behind is removed by the next one.
"""

import fcntl
import ipaddress
import json
import os
import re
import shutil
import subprocess
import tempfile

LANS = range(256)
"""LAN numbers: the third byte of the subnet."""
SUBNET = '10.213.{}.0/24'
NAMESPACE = 'fjsp{lan}-{host}'
BRIDGE = 'fjbr{lan}'
HOST_SIDE = 'fjh{lan}x{index}'
"""The bridge's end of a host's veth pair (interface names have at most 15 characters)."""
HOST_INTERFACE = 'eth0'
OUR_NAMESPACE = re.compile(r'fjsp(\d+)-')
OUR_LINK = re.compile(r'fj(?:br|h)(\d+)(?:x\d+)?$')
"""The LAN number is the first number in the name of a namespace or interface made here."""
MAX_HOSTS = 200


class HostsUnavailableError(RuntimeError):
    """Network namespaces cannot be created here; the message says why."""


def _lock_path(lan: int) -> str:
    return f'{tempfile.gettempdir()}/fjsp-lan-{lan}.lock'


def _ip(*args, check: bool = True) -> subprocess.CompletedProcess:
    done = subprocess.run(['ip', *args], capture_output=True, text=True, timeout=30)
    if check and done.returncode != 0:
        raise RuntimeError(f"ip {' '.join(args)}: {done.stderr.strip() or done.returncode}")
    return done


def _namespaces() -> list[str]:
    out = _ip('-json', 'netns', 'list', check=False).stdout.strip()
    return [n['name'] for n in json.loads(out)] if out else []


def _links() -> list[str]:
    out = _ip('-json', 'link', 'show', check=False).stdout.strip()
    return [link['ifname'] for link in json.loads(out)] if out else []


def _remove(lan: int) -> None:
    """Every namespace and interface of LAN `lan`. Deleting one end of a veth pair deletes
    the other; a namespace goes once its last process has ended."""
    for link in _links():
        if (match := OUR_LINK.match(link)) and int(match.group(1)) == lan:
            _ip('link', 'del', link, check=False)
    for namespace in _namespaces():
        if (match := OUR_NAMESPACE.match(namespace)) and int(match.group(1)) == lan:
            _ip('netns', 'del', namespace, check=False)


def _try_lock(lan: int):
    lock = open(_lock_path(lan), 'w')  # noqa: SIM115  held for the LAN's lifetime
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        lock.close()
        return None
    return lock


def remove_abandoned() -> None:
    """Remove what runs that were killed before they could clean up left behind: the LANs
    whose lock nobody holds."""
    found = {int(m.group(1)) for name in _links() if (m := OUR_LINK.match(name))}
    found |= {int(m.group(1)) for name in _namespaces() if (m := OUR_NAMESPACE.match(name))}
    for lan in found:
        lock = _try_lock(lan)
        if lock is not None:
            _remove(lan)
            lock.close()


def _in_use(subnet: ipaddress.IPv4Network) -> bool:
    """Whether this machine already routes (part of) `subnet`."""
    out = _ip('-json', '-4', 'route', 'show', 'table', 'all', check=False).stdout.strip()
    for route in json.loads(out) if out else []:
        destination = route.get('dst', 'default')
        if destination == 'default':
            continue
        try:
            if ipaddress.ip_network(destination, strict=False).overlaps(subnet):
                return True
        except ValueError:
            continue
    return False


def check_available() -> None:
    """Raise `HostsUnavailableError` saying why network namespaces cannot be made here."""
    if shutil.which('ip') is None:
        raise HostsUnavailableError("iproute2's 'ip' command is not installed "
                                    '(Debian: apt-get install iproute2)')
    if os.geteuid() != 0:
        raise HostsUnavailableError('network namespaces need root (CAP_SYS_ADMIN and '
                                    f'CAP_NET_ADMIN); this runs as uid {os.geteuid()}')


class Host:
    """One simulated host: its namespace, address and the bridge port its link plugs into."""

    def __init__(self, name: str, namespace: str, address: str, port: str):
        self.name = name
        self.namespace = namespace
        self.address = address
        self.port = port

    @property
    def prefix(self) -> list[str]:
        """The command prefix that runs a command on this host."""
        return ['ip', 'netns', 'exec', self.namespace]

    def __repr__(self) -> str:
        return f'Host({self.name!r}, {self.address}, namespace {self.namespace!r})'


class Network:
    """A LAN of hosts: a bridge in this machine's namespace (address `.1`: this machine is
    on the LAN too, so a test process here sees every host) and one namespace per host.

    Multicast snooping is off on the bridge, so DDS discovery multicast reaches every host
    whatever IGMP state a pulled link left behind."""

    def __init__(self):
        check_available()
        remove_abandoned()
        self.hosts: dict[str, Host] = {}
        self._lock = None
        for lan in LANS:
            lock = _try_lock(lan)
            if lock is None:
                continue
            _remove(lan)  # left by a run that died holding this number
            subnet = ipaddress.ip_network(SUBNET.format(lan))
            if _in_use(subnet):
                lock.close()
                continue
            self.lan, self.subnet, self._lock = lan, subnet, lock
            break
        else:
            raise HostsUnavailableError(f'every LAN number {LANS.start}..{LANS.stop - 1} is '
                                        'in use or its subnet is routed already')
        self.bridge = BRIDGE.format(lan=self.lan)
        self.gateway = str(self.subnet.network_address + 1)
        try:
            _ip('link', 'add', self.bridge, 'type', 'bridge', 'mcast_snooping', '0')
        except RuntimeError as error:
            self.close()
            raise HostsUnavailableError(f'cannot create a bridge: {error}') from None
        try:
            _ip('addr', 'add', f'{self.gateway}/{self.subnet.prefixlen}', 'dev', self.bridge)
            _ip('link', 'set', self.bridge, 'up')
        except BaseException:
            self.close()
            raise

    def host(self, name: str) -> Host:
        """The host called `name`, made on first use."""
        if name in self.hosts:
            return self.hosts[name]
        if len(self.hosts) >= MAX_HOSTS:
            raise ValueError(f'a LAN has at most {MAX_HOSTS} hosts')
        index = len(self.hosts) + 1
        namespace = NAMESPACE.format(lan=self.lan, host=re.sub(r'[^A-Za-z0-9_.-]', '_', name))
        port = HOST_SIDE.format(lan=self.lan, index=index)
        address = str(self.subnet.network_address + 1 + index)
        try:
            _ip('netns', 'add', namespace)
        except RuntimeError as error:
            raise HostsUnavailableError(f'cannot create a network namespace: {error}') from None
        self.hosts[name] = host = Host(name, namespace, address, port)
        _ip('link', 'add', port, 'type', 'veth', 'peer', 'name', HOST_INTERFACE,
            'netns', namespace)
        _ip('link', 'set', port, 'master', self.bridge, 'up')
        inside = ('-n', namespace)
        _ip(*inside, 'addr', 'add', f'{address}/{self.subnet.prefixlen}', 'dev', HOST_INTERFACE)
        _ip(*inside, 'link', 'set', HOST_INTERFACE, 'up')
        _ip(*inside, 'link', 'set', 'lo', 'up')
        # This machine's other addresses (those a test process here announces to DDS) are
        # reached through the bridge.
        _ip(*inside, 'route', 'add', 'default', 'via', self.gateway)
        return host

    def cut(self, name: str) -> None:
        """Pull host `name`'s cable at the switch: its interface stays up, nothing gets
        through until `restore`."""
        _ip('link', 'set', self.hosts[name].port, 'down')

    def restore(self, name: str) -> None:
        _ip('link', 'set', self.hosts[name].port, 'up')

    def close(self) -> None:
        """Remove every namespace and interface of this LAN. The processes still running
        on a host keep its namespace alive until they end, cut off from everything."""
        if self._lock is None:
            return
        try:
            _remove(self.lan)
        finally:
            self._lock.close()
            self._lock = None

    def __enter__(self) -> 'Network':
        return self

    def __exit__(self, *exc) -> None:
        self.close()

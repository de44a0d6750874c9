"""The live web page's server: the page itself (plain HTML, CSS and JS shipped with the
package, nothing fetched from elsewhere, since fleet machines often have no internet) and a
stream of updates to every open page as server-sent events.

The monitor publishes the page's data as named parts (`mission`, `robots`, `map`,
`timeline`, `story`, `missions`). The page itself comes with the mission written in and every
part embedded (`page`), so it shows the mission on first load, without JavaScript too; its
script then receives every part when it connects to the stream, and after that only the
parts that changed, each as soon as it changed. Server-sent events are plain HTTP, reconnect by
themselves, and need no library on either side. The server runs on its own threads; the
monitor's executor only calls `publish`.
"""

import json
import sys
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

from fjsp_planner.observe.page import render

WEB = Path(__file__).resolve().parent / 'web'
PAGE = WEB / 'index.html'
PAGE_PATHS = ('/', '/index.html')
FILES = {'/dashboard.js': ('dashboard.js', 'text/javascript; charset=utf-8'),
         '/dashboard.css': ('dashboard.css', 'text/css; charset=utf-8')}
KEEPALIVE = 15.0
"""Seconds between comments sent to an idle page, so a closed one is noticed."""


class _Server(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address):
        """A page closed mid-request is routine; anything else is reported as usual."""
        if not isinstance(sys.exc_info()[1], ConnectionError):
            super().handle_error(request, client_address)


class Dashboard:
    """An HTTP server for the page and its updates; `publish` the data, `close` when done."""

    def __init__(self, host: str = '127.0.0.1', port: int = 8080):
        """Binds at once: raises OSError if the address is taken or not allowed."""
        self._parts: dict[str, str] = {}
        self._changed_at: dict[str, int] = {}
        self._version = 0
        self._closing = False
        self._condition = threading.Condition()
        self._server = _Server((host, port), self._handler())
        self._thread = threading.Thread(target=self._server.serve_forever,
                                        name='dashboard', daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        host, port = self._server.server_address[:2]
        return f'http://{host}:{port}/'

    def publish(self, parts: dict) -> list[str]:
        """Make `parts` (name -> JSON-ready data) the page's data; the names that changed."""
        encoded = {name: json.dumps(data, separators=(',', ':'), allow_nan=False)
                   for name, data in parts.items()}
        with self._condition:
            changed = [name for name, text in encoded.items() if self._parts.get(name) != text]
            if changed:
                self._version += 1
                for name in changed:
                    self._parts[name] = encoded[name]
                    self._changed_at[name] = self._version
                self._condition.notify_all()
        return changed

    def close(self) -> None:
        with self._condition:
            self._closing = True
            self._condition.notify_all()
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=2.0)

    def page(self) -> str:
        """The page with the current parts written in."""
        with self._condition:
            parts = {name: json.loads(text) for name, text in self._parts.items()}
        return render(PAGE.read_text(), parts)

    def _since(self, version: int) -> tuple[int, str | None]:
        """The current version, and the parts changed after `version` as one JSON object."""
        names = [n for n, v in self._changed_at.items() if v > version]
        if not names:
            return self._version, None
        return self._version, '{' + ','.join(f'"{n}":{self._parts[n]}' for n in names) + '}'

    def _stream(self, write) -> None:
        """Send the updates to one page until it goes away or the server closes."""
        seen = 0
        while True:
            with self._condition:
                self._condition.wait_for(lambda seen=seen: self._closing or self._version > seen,
                                         timeout=KEEPALIVE)
                if self._closing:
                    return
                seen, update = self._since(seen)
            write(f'event: update\ndata: {update}\n\n' if update else ': keepalive\n\n')

    def _handler(self):
        dashboard = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = 'HTTP/1.1'

            def do_GET(self):  # noqa: N802  (the name http.server calls)
                path = self.path.split('?', 1)[0]
                if path in PAGE_PATHS:
                    self._send(HTTPStatus.OK, 'text/html; charset=utf-8',
                               dashboard.page().encode())
                elif path in FILES:
                    name, kind = FILES[path]
                    self._send(HTTPStatus.OK, kind, (WEB / name).read_bytes())
                elif path == '/state':
                    with dashboard._condition:
                        _, state = dashboard._since(0)
                    self._send(HTTPStatus.OK, 'application/json', (state or '{}').encode())
                elif path == '/events':
                    self._events()
                else:
                    self._send(HTTPStatus.NOT_FOUND, 'text/plain; charset=utf-8',
                               f'no page {path}\n'.encode())

            def _send(self, status, kind, body: bytes):
                self.send_response(status)
                self.send_header('Content-Type', kind)
                self.send_header('Content-Length', str(len(body)))
                self.send_header('Cache-Control', 'no-store')
                self.end_headers()
                self.wfile.write(body)

            def _events(self):
                self.send_response(HTTPStatus.OK)
                self.send_header('Content-Type', 'text/event-stream')
                self.send_header('Cache-Control', 'no-store')
                self.send_header('Connection', 'close')
                self.end_headers()
                self.close_connection = True

                def write(text: str):
                    self.wfile.write(text.encode())
                    self.wfile.flush()

                try:
                    dashboard._stream(write)
                except (ConnectionError, TimeoutError):
                    pass

            def log_message(self, format, *args):  # noqa: A002  (http.server's signature)
                pass  # the monitor's log is for the mission, not for page requests

        return Handler

"""A local chat-completions server for tests: it speaks the OpenAI protocol
on 127.0.0.1 and answers each request with the next scripted behaviour."""

import http.server
import json
import threading
import time
from typing import Callable, List, Union


class Reply(str):
    """Answer with this content."""


class Sleep:
    """Answer with `content` after `seconds` (longer than the client's timeout: a timeout)."""

    def __init__(self, seconds: float, content: str = "ACTION: up"):
        self.seconds = seconds
        self.content = content


class Close:
    """Close the connection without answering."""


class Status:
    """Answer with an HTTP error status."""

    def __init__(self, code: int):
        self.code = code


class Garbage:
    """Answer 200 with a body that is not a chat-completions answer."""


Behaviour = Union[Reply, Sleep, Close, Status, Garbage]


class ChatStub:
    """with ChatStub(script) as stub: ... stub.url ...; script: a list of
    behaviours (then `default` forever), or a function of the request's JSON."""

    def __init__(self, script: Union[List[Behaviour], Callable[[dict], Behaviour]], default: Behaviour = Close()):
        self.requests: List[dict] = []
        self._script = script
        self._default = default
        self._lock = threading.Lock()
        stub = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_POST(self):
                length = int(self.headers.get("Content-Length", 0))
                request = json.loads(self.rfile.read(length))
                behaviour = stub._next(request, self.path)
                if isinstance(behaviour, Close):
                    self.close_connection = True
                    return  # no status line: the client sees the connection drop
                if isinstance(behaviour, Status):
                    self._send(behaviour.code, b'{"error": {"message": "scripted failure"}}')
                    return
                if isinstance(behaviour, Garbage):
                    self._send(200, b'{"not": "an answer"}')
                    return
                content = behaviour
                if isinstance(behaviour, Sleep):
                    time.sleep(behaviour.seconds)
                    content = behaviour.content
                answer = {
                    "id": "stub",
                    "object": "chat.completion",
                    "model": request.get("model"),
                    "choices": [{"index": 0, "message": {"role": "assistant", "content": str(content)},
                                 "finish_reason": "stop"}],
                }
                self._send(200, json.dumps(answer).encode())

            def _send(self, code: int, body: bytes):
                try:
                    self.send_response(code)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(body)))
                    self.end_headers()
                    self.wfile.write(body)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the client gave up (a timeout test)

        self._server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._server.daemon_threads = True
        self.url = f"http://127.0.0.1:{self._server.server_address[1]}/v1"
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)

    def _next(self, request: dict, path: str) -> Behaviour:
        with self._lock:
            self.requests.append({"path": path, **request})
            if callable(self._script):
                return self._script(request)
            return self._script.pop(0) if self._script else self._default

    def __enter__(self) -> "ChatStub":
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._server.shutdown()
        self._server.server_close()

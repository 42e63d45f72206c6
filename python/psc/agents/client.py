"""A client for OpenAI-compatible chat-completions endpoints (OpenAI, vLLM,
llama.cpp's server, ...) over the standard library's HTTP: no dependency."""

import http.client
import json
import socket
import time
import urllib.error
import urllib.request
from dataclasses import dataclass
from typing import List, Optional

RETRIED_HTTP_STATUSES = (408, 409, 425, 429, 500, 502, 503, 504)


class ChatError(RuntimeError):
    """A request failed for good (after its retries); the message says why."""


def completions_url(endpoint: str) -> str:
    """The chat-completions URL of an endpoint given as a base (http://host:port
    or http://host:port/v1) or as the full .../chat/completions URL."""
    url = endpoint.rstrip("/")
    if url.endswith("/chat/completions"):
        return url
    if not url.endswith("/v1"):
        url += "/v1"
    return url + "/chat/completions"


@dataclass
class ChatClient:
    """POSTs chat-completions requests; thread-safe (one connection per request).

    timeout: seconds per attempt; retries: further attempts after a timeout, a
    dropped connection, a retryable HTTP status (429, 5xx, ...) or an
    unreadable answer, waiting backoff * 2**attempt seconds between them."""

    endpoint: str
    model: str
    api_key: Optional[str] = None
    temperature: float = 0.0
    max_tokens: Optional[int] = None
    timeout: float = 60.0
    retries: int = 2
    backoff: float = 0.5

    def __post_init__(self):
        self.url = completions_url(self.endpoint)

    def complete(self, messages: List[dict], seed: Optional[int] = None) -> str:
        """The first choice's message content; ChatError when every attempt failed."""
        body = {"model": self.model, "messages": messages, "temperature": self.temperature}
        if self.max_tokens is not None:
            body["max_tokens"] = self.max_tokens
        if seed is not None:
            body["seed"] = int(seed)
        data = json.dumps(body).encode("utf-8")
        headers = {"Content-Type": "application/json"}
        if self.api_key:
            headers["Authorization"] = f"Bearer {self.api_key}"
        failures = []
        for attempt in range(self.retries + 1):
            if attempt:
                time.sleep(self.backoff * 2 ** (attempt - 1))
            try:
                return self._attempt(data, headers)
            except _Retryable as e:
                failures.append(str(e))
            except _Fatal as e:
                raise ChatError(f"{self.url}: {e}") from None
        raise ChatError(f"{self.url}: {len(failures)} attempts failed: " + "; ".join(failures))

    def _attempt(self, data: bytes, headers: dict) -> str:
        request = urllib.request.Request(self.url, data=data, headers=headers, method="POST")
        try:
            with urllib.request.urlopen(request, timeout=self.timeout) as response:
                raw = response.read()
        except urllib.error.HTTPError as e:
            detail = e.read().decode("utf-8", "replace")[:300]
            kind = _Retryable if e.code in RETRIED_HTTP_STATUSES else _Fatal
            raise kind(f"HTTP {e.code}: {detail}") from None
        except (socket.timeout, TimeoutError):
            raise _Retryable(f"no answer within {self.timeout} s") from None
        except urllib.error.URLError as e:
            if isinstance(e.reason, (socket.timeout, TimeoutError)):
                raise _Retryable(f"no answer within {self.timeout} s") from None
            raise _Retryable(f"connection failed: {e.reason}") from None
        except (http.client.HTTPException, ConnectionError, OSError) as e:
            raise _Retryable(f"connection dropped: {type(e).__name__}: {e}") from None
        try:
            answer = json.loads(raw)
            content = answer["choices"][0]["message"]["content"]
        except (ValueError, KeyError, IndexError, TypeError):
            raise _Retryable(f"not a chat-completions answer: {raw[:200]!r}") from None
        if not isinstance(content, str):
            raise _Retryable(f"the answer's content is not text: {content!r}"[:300])
        return content


class _Retryable(Exception):
    pass


class _Fatal(Exception):
    pass

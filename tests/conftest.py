"""Shared test helpers."""

import os
import signal
import time

import pytest


@pytest.fixture
def kill_a_busy_worker():
    """``make(client) -> (progress, killed)``: a ``progress(task, done)`` callback that, the first time it
    is called, waits (bounded) until some worker of ``client`` is running a task and SIGKILLs that
    worker's process; ``killed`` lists the workers it killed (one at most)."""

    def make(client):
        killed = []

        def progress(task, done):
            if killed:
                return
            for _ in range(200):
                busy = [w for w, keys in client.processing().items() if keys]
                if busy:
                    pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                    os.kill(pid, signal.SIGKILL)
                    killed.append(busy[0])
                    return
                time.sleep(0.05)

        return progress, killed

    return make

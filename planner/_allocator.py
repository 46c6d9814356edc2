"""Freed memory kept for the next frame: the frame's large arrays cost no page faults.

A frame of a large crowd allocates tens of MB of arrays and frees them again (the local maps of
every planning character, 12 MB a frame for 1000 spiders with LOD on, 80 MB with LOD off; the
requests' and results' arrays). glibc's ``malloc`` maps an array that large straight from the
kernel and gives it back when it is freed, so the next frame's array of the same size starts from
fresh pages, each zeroed by the kernel on its first write: about 3,000 page faults a frame for
1000 spiders with LOD on, 8-14 ms of system time per frame (issue 15). Keeping freed memory in the
process (``mallopt``: a high ``M_MMAP_THRESHOLD``, so such arrays come from the heap, and a high
``M_TRIM_THRESHOLD``, so the heap keeps what is freed) takes them to 1 a frame: 1000 spiders, LOD
on, a program that only steps the crowd, 50-56 -> 45-46 ms per frame (the same runs, alternating;
docs/performance.md). ``footfall simulate`` gains less (a few %): its per-frame metrics keep part of that
memory in use anyway. Results do not depend on it. The price is memory: the process keeps its largest
frame's worth of arrays after they are freed.

Only glibc (Linux) has these settings; elsewhere, or with ``FOOTFALL_KEEP_FREED_MEMORY=0``, nothing
changes.
"""

from __future__ import annotations

import ctypes
import os
import sys

M_TRIM_THRESHOLD = -1  # glibc <malloc.h>
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLDS = (1 << 30, 256 << 20, 32 << 20)
"""Bytes: the highest of these that this glibc accepts is the size up to which arrays come from the heap."""


def keep_freed_memory() -> bool:
    """Ask glibc to keep freed memory for the next allocations (module doc). Returns whether it was set:
    False off glibc or with ``FOOTFALL_KEEP_FREED_MEMORY=0``."""
    if os.environ.get("FOOTFALL_KEEP_FREED_MEMORY", "1") == "0" or not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL("libc.so.6").mallopt
    except (OSError, AttributeError):  # not glibc (musl, ...)
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    for threshold in MMAP_THRESHOLDS:
        if mallopt(M_MMAP_THRESHOLD, threshold):
            return bool(mallopt(M_TRIM_THRESHOLD, min(2 * threshold, (1 << 31) - 1)))
    return False

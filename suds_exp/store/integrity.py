"""Refuse a damaged DuckDB file before anything reads or writes it.

DuckDB opens a file cut short, or one with a damaged data block, as long as its catalog
is intact, and fails only when a query reaches the missing or damaged block, possibly
after a write began. So before a file is opened this module checks what DuckDB's own
format promises (``src/storage/single_file_block_manager.cpp``):

- 3 header sectors of 4 KiB: the main header (``DUCK`` magic at byte 8) and two
  database headers, each starting with the 64-bit checksum of the rest of its sector;
  the one with the higher iteration counter is the current one and records the number
  of blocks (``block_count``) and their size (``block_alloc_size``);
- then ``block_count`` blocks, each starting with the checksum of the rest of the block;
  the header's ``free_list`` points to the list of the free ones in the metadata blocks
  (blocks cut in 64 sub-blocks, each starting with a pointer to the next). DuckDB cuts
  free blocks off the end of the file, so only the blocks in use must be there.

Every open checks the headers, reads the free list and checks that the file is long
enough for every block in use (a few KiB read: a truncated copy is refused). When the
file's size or modification time is not what this process left it at, every block in
use has its checksum checked too, vectorised with NumPy: 0.4-0.5 s for a 280 MB file
on this project's machine (``suds_exp.testing.reliability_probe`` measures it), against
~1 s to import the library. So a command checks each block once, and a long campaign does not
re-check after each of its own writes. Free blocks and blocks past ``block_count``
(left by a checkpoint a crash cut short) are not checked: DuckDB does not read them.
Files of a storage format this module does not know (`KNOWN_FORMATS`) or encrypted ones
get only the magic check; DuckDB's own checks cover them.
"""

from __future__ import annotations

import struct
import threading
import time
from pathlib import Path

import numpy as np

from suds_exp.errors import StoreError

SECTOR_BYTES = 4096
HEADER_BYTES = 3 * SECTOR_BYTES
_MAGIC = b"DUCK"
#: Storage format numbers (main header, byte 12) whose layout is the one read here:
#: DuckDB 0.10-1.1 (64), 1.2 (65), 1.3 (66), 1.4 (67), and 999 ("latest" in 2.0).
KNOWN_FORMATS = frozenset({64, 65, 66, 67, 999})
_MULTIPLIER = np.uint64(0xBF58476D1CE4E5B9)
_SEED = np.uint64(5381)
#: Blocks hashed per read (x 256 KiB = 16 MiB at the default block size).
_CHUNK_BLOCKS = 64

#: resolved path -> (size, mtime_ns) of a file whose blocks this process checked or wrote
_verified: dict[str, tuple[int, int]] = {}
_guard = threading.Lock()


class Damaged(StoreError):
    """Raised by `check_file`: the file is not a DuckDB database, or a damaged one."""


def checksum(words: np.ndarray) -> np.ndarray:
    """DuckDB's checksum of each row of ``words`` (uint64, shape (n_blocks, n_words)):
    5381 xor-ed with every word times 0xbf58476d1ce4e5b9 (mod 2**64). Shape (n_blocks,)."""
    with np.errstate(over="ignore"):
        return np.bitwise_xor.reduce(words * _MULTIPLIER, axis=1) ^ _SEED


def _damaged(path: Path, what: str) -> Damaged:
    return Damaged(
        f"{path}: the database file is truncated or damaged ({what}); nothing was read or "
        "written; restore it from a copy"
    )


def read_header(path: Path, head: bytes, size: int) -> tuple[int, int, int]:
    """(block_count, block_size in bytes, free list pointer) of the current database
    header in ``head`` (the file's first 12 KiB); raises `Damaged` for a header DuckDB
    would not accept."""
    if len(head) < HEADER_BYTES:
        raise _damaged(path, f"{size} bytes, shorter than DuckDB's {HEADER_BYTES}-byte header")
    current = None
    for i in (1, 2):
        sector = np.frombuffer(head[i * SECTOR_BYTES : (i + 1) * SECTOR_BYTES], dtype="<u8")
        if int(checksum(sector[None, 1:])[0]) != int(sector[0]):
            raise _damaged(path, f"database header {i} fails its checksum")
        iteration, _, free, count, block_size = struct.unpack_from(
            "<QQQQQ", head, i * SECTOR_BYTES + 8
        )
        if current is None or iteration > current[0]:
            current = (iteration, count, block_size, free)
    _, count, block_size, free = current
    if count == 0:
        return 0, block_size, _NO_POINTER
    if block_size < SECTOR_BYTES or block_size % SECTOR_BYTES or block_size > 1 << 30:
        raise _damaged(path, f"block size {block_size} in its header")
    return count, block_size, free


_NO_POINTER = 0xFFFF_FFFF_FFFF_FFFF
_SUB_BLOCKS = 64


def free_blocks(path: Path, f, count: int, block_size: int, pointer: int) -> set[int]:
    """The ids of the free blocks listed at metadata pointer ``pointer`` of the open file
    ``f`` (block id in the low 56 bits, sub-block index in the high 8)."""
    sub = (block_size - 8) // _SUB_BLOCKS // 8 * 8
    data = bytearray()
    for _ in range(count * _SUB_BLOCKS + 1):
        if pointer == _NO_POINTER:
            break
        block, index = pointer & ((1 << 56) - 1), pointer >> 56
        if block >= count or index >= _SUB_BLOCKS:
            raise _damaged(path, "its free list points outside the file")
        f.seek(HEADER_BYTES + block * block_size + 8 + index * sub)
        chunk = f.read(sub)
        if len(chunk) < sub:
            raise _damaged(path, f"block {block} of its free list is missing: truncated")
        pointer = struct.unpack_from("<Q", chunk)[0]
        data += chunk[8:]
    else:
        raise _damaged(path, "its free list loops")
    if len(data) < 8:
        return set()
    n = struct.unpack_from("<Q", data)[0]
    if 8 + 8 * n > len(data):
        raise _damaged(path, "its free list is longer than its blocks")
    return set(struct.unpack_from(f"<{n}q", data, 8))


#: Checks of a file another process changed meanwhile (a writer's checkpoint can free
#: and reuse blocks, or cut the file, while it is read) before a fault is believed.
ATTEMPTS = 3


def check_file(path: Path, blocks: bool = True) -> None:
    """Raise `Damaged` (one line naming ``path``) for an existing file that is not a
    DuckDB database, whose headers fail their checksums, that is shorter than its header
    says, or (``blocks``, once per file and process) one of whose blocks fails its
    checksum. A missing or empty file passes (DuckDB creates it). A fault found while the
    file changed (another process wrote it) is checked again, up to `ATTEMPTS` times."""
    for attempt in range(ATTEMPTS):
        try:
            before = path.stat()
            _check_once(path, blocks)
            return
        except Damaged:
            try:
                after = path.stat()
            except OSError:
                return
            if attempt == ATTEMPTS - 1 or (before.st_size, before.st_mtime_ns) == (
                after.st_size,
                after.st_mtime_ns,
            ):
                raise
            time.sleep(0.2)
        except OSError:
            return  # DuckDB's own open names the problem (no such file, permission, ...)


def _check_once(path: Path, blocks: bool) -> None:
    try:
        if not path.is_file():
            return
        stat = path.stat()
        size = stat.st_size
        if size == 0:
            return
        with path.open("rb") as f:
            head = f.read(HEADER_BYTES)
    except OSError:
        return  # DuckDB's own open names the problem (permission, ...)
    if head[8:12] != _MAGIC:
        raise Damaged(f"{path}: not a DuckDB database file")
    if len(head) >= 28:
        fmt, flags = struct.unpack_from("<QQ", head, 12)
        if fmt not in KNOWN_FORMATS or flags:
            return
    count, block_size, pointer = read_header(path, head, size)
    if count == 0:
        return
    try:
        with path.open("rb") as f:
            free = free_blocks(path, f, count, block_size, pointer)
    except OSError:
        return
    used = np.setdiff1d(np.arange(count), np.fromiter(free, dtype=np.int64, count=len(free)))
    need = HEADER_BYTES + (int(used[-1]) + 1) * block_size if len(used) else HEADER_BYTES
    if size < need:
        raise _damaged(path, f"{size} bytes, shorter than the {need} its blocks in use need")
    key = str(path.resolve())
    with _guard:
        if not blocks or _verified.get(key) == (size, stat.st_mtime_ns):
            return
    bad = bad_blocks(path, used, block_size)
    if bad:
        where = ", ".join(str(b) for b in bad[:5]) + (" ..." if len(bad) > 5 else "")
        raise _damaged(path, f"{len(bad)} of {len(used)} blocks fail their checksum: block {where}")
    with _guard:
        _verified[key] = (size, stat.st_mtime_ns)


def mark_written(path: Path) -> None:
    """Record ``path`` as it is now as checked: this process just wrote it."""
    try:
        stat = path.stat()
    except OSError:
        return
    with _guard:
        _verified[str(path.resolve())] = (stat.st_size, stat.st_mtime_ns)


def bad_blocks(path: Path, used: np.ndarray, block_size: int) -> list[int]:
    """The ids among ``used`` (sorted block ids) of the blocks of ``path`` whose checksum
    does not match (free blocks are not checked: DuckDB may reuse them half-written)."""
    bad: list[int] = []
    words = block_size // 8
    count = int(used[-1]) + 1 if len(used) else 0
    with path.open("rb") as f:
        f.seek(HEADER_BYTES)
        done = 0
        while done < count:
            n = min(_CHUNK_BLOCKS, count - done)
            buf = f.read(n * block_size)
            ids = used[(used >= done) & (used < done + n)]
            if len(buf) < n * block_size:
                return [*bad, *ids.tolist()]
            a = np.frombuffer(buf, dtype="<u8").reshape(n, words)[ids - done]
            bad += ids[checksum(a[:, 1:]) != a[:, 0]].tolist()
            done += n
    return bad

"""Where a key of a TOML file is written: 'FILE:LINE' for error messages (tomllib gives no positions).

A best-effort scan of the text: table headers ``[a.b]`` and ``[[a.b]]`` (the k-th of an array of
tables) and ``key =`` lines below them.  A key written inside an inline table is found at the line of
the key that holds the inline table.
"""
from __future__ import annotations

import re
from pathlib import Path

_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")


def _norm(name: str) -> str:
    return ".".join(part.strip().strip('"').strip("'") for part in re.split(r"\.(?=(?:[^\"]*\"[^\"]*\")*[^\"]*$)",
                                                                             name))


class Lines:
    """The headers and keys of one TOML text."""

    def __init__(self, path: Path, text: str):
        self.path = path
        self.lines = text.splitlines()
        self.headers: list[tuple[int, str, bool]] = []   # (line number, table name, array of tables)
        for n, line in enumerate(self.lines, 1):
            m = _HEADER.match(line)
            if m and not line.lstrip().startswith("#"):
                self.headers.append((n, _norm(m.group(2)), m.group(1) == "[["))

    def _section(self, table: str, index: int | None) -> tuple[int, int] | None:
        """(first line, last line) of table ``table`` (the index-th of an array of tables)."""
        if not table:
            end = self.headers[0][0] - 1 if self.headers else len(self.lines)
            return 1, end
        count = -1
        for k, (n, name, array) in enumerate(self.headers):
            if name != table:
                continue
            count += 1
            if index is None or count == index:
                end = self.headers[k + 1][0] - 1 if k + 1 < len(self.headers) else len(self.lines)
                return n, end
        return None

    def find(self, table: str = "", key: str | None = None, index: int | None = None) -> int | None:
        """The line of ``key`` in ``table`` (dotted; '' = the top), or of the table's header, or of the
        key holding ``table`` inline (e.g. ``commands = [...]``); None if not found."""
        section = self._section(table, index)
        if section is None:
            head, _, last = table.rpartition(".")
            return self.find(head, last) if last else None
        first, end = section
        if key is not None:
            pattern = re.compile(r"^\s*[\"']?" + re.escape(key) + r"[\"']?\s*=")
            for n in range(first, end + 1):
                if pattern.match(self.lines[n - 1]):
                    return n
            # a key inside an inline table of this section: its line
            inline = re.compile(r"[{,]\s*[\"']?" + re.escape(key) + r"[\"']?\s*=")
            for n in range(first, end + 1):
                if inline.search(self.lines[n - 1]):
                    return n
            # a key written as a table of its own: [table.key]
            sub = self._section(f"{table}.{key}" if table else key, None)
            if sub is not None:
                return sub[0]
        return first if table else None

    def at(self, table: str = "", key: str | None = None, index: int | None = None) -> str:
        """'FILE:LINE' (or 'FILE' where the line is not known)."""
        n = self.find(table, key, index)
        return f"{self.path}:{n}" if n else str(self.path)

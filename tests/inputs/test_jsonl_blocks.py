"""The block reader of JSON Lines (``battgen validate``'s) reads what the line reader reads: the same values
(of the same types), line numbers and unreadable lines, on every kind of line either path may take."""

from __future__ import annotations

import json
import os
import threading
from pathlib import Path

import pytest

from codegen.inputs.documents import MAX_LINE, read_jsonl
from codegen.inputs.jsonl_blocks import BLOCK, jsonl_blocks
from codegen.inputs.records import InputError, Record, Unreadable

RECORD = json.dumps({"a": 1, "b": [1.5, 2.25, -0.0], "c": "x", "d": None, "e": True})
LINE = RECORD + "\n"


def _blocks(path: Path) -> list[object]:
    out: list[object] = []
    for part in jsonl_blocks(path, "f.jsonl"):
        if isinstance(part, Unreadable):
            out.append(part)
        else:
            out += [(line, repr(value), [type(v) for v in _leaves(value)]) for line, value in part]
    return out


def _lines(path: Path) -> list[object]:
    out: list[object] = []
    for item in read_jsonl(path, "f.jsonl"):
        if isinstance(item, Record):
            out.append((item.line, repr(item.data), [type(v) for v in _leaves(item.data)]))
        else:
            out.append(item)
    return out


def _leaves(value: object) -> list[object]:
    if isinstance(value, dict):
        return [leaf for v in value.values() for leaf in _leaves(v)]
    if isinstance(value, list):
        return [leaf for v in value for leaf in _leaves(v)]
    return [value]


TEXTS = {
    "plain": LINE * 3,
    "blank lines": "\n\n" + LINE + "   \n\t\n" + RECORD,
    "byte order mark": "\ufeff" + LINE + LINE,
    "byte order mark later": LINE + "\ufeff" + LINE,
    "crlf": RECORD + "\r\n" + RECORD + "\r\n\r\n",
    "carriage returns": RECORD + "\r" + RECORD + "\r",
    "mixed ends": RECORD + "\r" + LINE + RECORD + "\r\n{bad\r\n" + RECORD,
    "errors": LINE + '{"a": \n[1,]\n"\\ud800"\n{"a": 1} x\n',
    "json's extensions": 'NaN\n{"x": Infinity}\n{"x": -Infinity}\n1e400\n',
    "integers beyond 64 bits": '{"t": 18446744073709551616}\n{"t": -9223372036854775809}\n'
    + '{"t": 1.00000000000000000000001}\n{"t": 12345678901234567890123}\n{"t": 18446744073709551615}\n'
    + LINE,
    "an integer json cannot convert": '{"t": ' + "9" * 5000 + "}\n" + LINE,
    "unicode blanks": "\u00a0\n\u2028\n" + LINE + "\x0c\n\x1c\n",
    "no final newline": LINE + RECORD,
    "empty": "",
    "nested deeper than json reads": "[" * 100_000 + "]" * 100_000 + "\n" + LINE,
    "control character": '"a\x01b"\n' + LINE,
    "spaces around": " " + RECORD + " \t\n",
    "text": '{"s": "é€😀\\n\\u00e9"}\n' * 3,
}


@pytest.mark.parametrize("long", [False, True], ids=["json alone", "orjson"])
@pytest.mark.parametrize("text", TEXTS.values(), ids=list(TEXTS))
def test_blocks_read_what_lines_read(tmp_path: Path, text: str, long: bool) -> None:
    """A file of one block is read by json alone; a longer one by orjson where it can, from its first line."""
    path = tmp_path / "f.jsonl"
    tail = "\n" + LINE * (BLOCK // len(LINE) + 1) if long else ""  # a few lines more than a block
    path.write_text(text + tail, encoding="utf-8", newline="")
    assert _blocks(path) == _lines(path)


BYTES = {
    "not UTF-8": LINE.encode() * 3 + b"\xff\xfe\n" + LINE.encode(),
    "not UTF-8 first": b"\xff\n" + LINE.encode(),
    "a line too long": LINE.encode() + b'"' + b"a" * (MAX_LINE + 10) + b'"\n' + LINE.encode(),
    "a line just long enough": LINE.encode() + b'"' + b"a" * (MAX_LINE - 3) + b'"\r\n' + LINE.encode(),
    "many blocks": (LINE * 10 + "\n{bad\n" + RECORD + "\r\n" + RECORD + "\r").encode() * 200,
    "a long line across blocks": LINE.encode() * 100 + b"[" + b"1.5," * BLOCK + b"1]\n" + LINE.encode() * 10,
    "carriage returns only": (RECORD + "\r").encode() * 200,
    "multibyte text across blocks": '{"s": "é€😀"}\n'.encode() * 3000,
}


@pytest.mark.parametrize("data", BYTES.values(), ids=list(BYTES))
def test_blocks_read_what_lines_read_of_odd_bytes(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "f.jsonl"
    path.write_bytes(data)
    assert _blocks(path) == _lines(path)


def test_blocks_of_a_file_that_cannot_be_opened(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="cannot read file") as info:
        list(jsonl_blocks(tmp_path / "absent.jsonl", "absent.jsonl"))
    assert (info.value.file, info.value.line) == ("absent.jsonl", 0)


CRASHERS = sorted((Path(__file__).resolve().parent.parent / "fuzz" / "crashers" / "read-jsonl").iterdir())


@pytest.mark.parametrize("crasher", CRASHERS, ids=[p.name for p in CRASHERS])
def test_blocks_read_what_lines_read_of_past_crashers(crasher: Path) -> None:
    assert _blocks(crasher) == _lines(crasher)


def test_blocks_of_a_pipe_hand_over_to_the_text_reader_without_seeking(tmp_path: Path) -> None:
    """A pipe (``battgen validate <(...)``) cannot be opened again at a line: the text reader is given the
    bytes read already, then the rest."""
    data = LINE.encode() * 3000 + b'"' + b"a" * (MAX_LINE + 5) + b'"\n' + LINE.encode() * 5
    read, write = os.pipe()
    writer = threading.Thread(target=_write_all, args=(write, data))
    writer.start()
    try:
        piped = _blocks(Path(f"/dev/fd/{read}"))
    finally:
        writer.join()
        os.close(read)
    path = tmp_path / "f.jsonl"
    path.write_bytes(data)
    assert piped == _lines(path)
    assert any(isinstance(item, Unreadable) and item.line == 3001 for item in piped)


def _write_all(fd: int, data: bytes) -> None:
    with os.fdopen(fd, "wb") as out:
        out.write(data)

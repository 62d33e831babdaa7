"""The .dtb reader (codegen.inputs.devicetree.read_dtb) on blobs we build by hand, and its error paths.

Blobs are assembled here from the devicetree specification's layout so the tests need no dtc;
conformance/test_dt_instances_dtschema.py reads what dtc itself writes.
"""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from codegen.inputs.devicetree import DevicetreeError, read_dtb, read_dtb_blob, read_dts, read_nodes

BEGIN, END_NODE, PROP, NOP, END = 1, 2, 3, 4, 9


def _pad(b: bytes) -> bytes:
    return b + b"\0" * (-len(b) % 4)


def build(
    structure: list[tuple[int, object]] | None = None,
    *,
    reservations: tuple[tuple[int, int], ...] = ((0x1000, 0x100),),
    version: int = 17,
    last_comp: int = 16,
    magic: int = 0xD00DFEED,
) -> bytes:
    """A blob: header, reservations, structure tokens ((token, arg) pairs), strings."""
    if structure is None:
        structure = [
            (BEGIN, ""),
            (PROP, ("compatible", b"acme,board\0")),
            (BEGIN, "battery@0"),
            (PROP, ("compatible", b"simple-battery\0")),
            (NOP, None),
            (PROP, ("voltage-min-design-microvolt", (3200000).to_bytes(4, "big"))),
            (PROP, ("present", b"")),
            (END_NODE, None),
            (END_NODE, None),
            (END, None),
        ]
    strings = b""
    offsets: dict[str, int] = {}
    body = b""
    for token, arg in structure:
        body += struct.pack(">I", token)
        if token == BEGIN:
            assert isinstance(arg, str)
            body += _pad(arg.encode() + b"\0")
        elif token == PROP:
            assert isinstance(arg, tuple)
            name, value = arg
            if name not in offsets:
                offsets[name] = len(strings)
                strings += name.encode() + b"\0"
            body += struct.pack(">II", len(value), offsets[name]) + _pad(value)
    rsv = b"".join(struct.pack(">QQ", a, s) for a, s in reservations) + bytes(16)
    off_rsv = 40
    off_struct = off_rsv + len(rsv)
    off_strings = off_struct + len(body)
    total = off_strings + len(strings)
    header = struct.pack(
        ">10I", magic, total, off_struct, off_strings, off_rsv, version, last_comp, 0, len(strings), len(body)
    )
    return header + rsv + body + strings


def _write(tmp_path: Path, data: bytes) -> Path:
    path = tmp_path / "b.dtb"
    path.write_bytes(data)
    return path


def test_reads_nodes_properties_and_reservations(tmp_path: Path) -> None:
    path = _write(tmp_path, build())
    blob = read_dtb_blob(path, root=tmp_path)
    assert blob.reservations == [(0x1000, 0x100)]
    assert blob.version == 17
    root, battery = blob.nodes
    assert root.path == "/" and battery.path == "/battery@0"
    assert battery.compatible == ["simple-battery"]
    assert battery.properties["voltage-min-design-microvolt"].cells() == [3200000]
    assert battery.properties["present"].is_flag
    assert (battery.file, battery.line, battery.properties["present"].parts) == ("b.dtb", 0, ())
    assert read_nodes(path) == read_dtb(path)


def test_same_nodes_as_the_source(tmp_path: Path) -> None:
    src = tmp_path / "s.dts"
    src.write_text(
        '/dts-v1/;\n/ { compatible = "acme,board";\n battery@0 { compatible = "simple-battery";'
        " voltage-min-design-microvolt = <3200000>; present; }; };\n"
    )
    dts = [(n.path, n.raw()) for n in read_dts(src)]
    dtb = [(n.path, n.raw()) for n in read_dtb(_write(tmp_path, build()))]
    assert dts == dtb


def test_version_16_blob_without_struct_size(tmp_path: Path) -> None:
    data = bytearray(build(version=16))
    struct.pack_into(">I", data, 36, 0)  # v16 has no size_dt_struct
    assert [n.path for n in read_dtb(_write(tmp_path, bytes(data)))] == ["/", "/battery@0"]


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"\xd0\x0d", "too short: expected a devicetree blob header"),
        (build(magic=0x12345678), r"magic 0x12345678: expected 0xd00dfeed"),
        (build()[:20], "truncated header"),
        (build(version=3, last_comp=2), "version 3 .* expected a version 16 or 17 blob"),
        (build(version=18, last_comp=18), "version 18"),
        (build()[:-8], r"truncated blob: header says \d+ bytes"),
        (build([(BEGIN, ""), (7, None)]), "unknown structure token 0x7"),
        (build([(BEGIN, ""), (END, None)]), "FDT_END with node / still open"),
        (build([(END_NODE, None)]), "FDT_END_NODE without an open node"),
        (build([(PROP, ("x", b"")), (END, None)]), "property outside any node"),
        (build([(BEGIN, "x"), (END_NODE, None), (END, None)]), "root node named 'x'"),
        (build([(BEGIN, ""), (END_NODE, None), (BEGIN, ""), (END_NODE, None), (END, None)]), "a second root node"),
        (build([(BEGIN, ""), (PROP, ("a", b"1")), (PROP, ("a", b"2")), (END_NODE, None), (END, None)]), "twice"),
        (build([(END, None)]), "no root node"),
    ],
)
def test_errors(tmp_path: Path, data: bytes, message: str) -> None:
    with pytest.raises(DevicetreeError, match=message) as info:
        read_dtb(_write(tmp_path, data), root=tmp_path)
    assert (info.value.file, info.value.line) == ("b.dtb", 0)
    assert info.value.message.startswith("byte 0x")


def test_struct_block_cut_short(tmp_path: Path) -> None:
    data = bytearray(build([(BEGIN, ""), (END_NODE, None)]))  # no FDT_END
    with pytest.raises(DevicetreeError, match="ends inside a token"):
        read_dtb(_write(tmp_path, bytes(data)))


def test_bad_name_offset_and_block_bounds(tmp_path: Path) -> None:
    data = bytearray(build())
    off_struct = struct.unpack_from(">I", data, 8)[0]
    # First PROP after BEGIN "" (4 + 4 bytes): its nameoff is at +8 from the PROP token.
    struct.pack_into(">I", data, off_struct + 8 + 8, 9999)
    with pytest.raises(DevicetreeError, match="name offset 9999 lies outside the strings block"):
        read_dtb(_write(tmp_path, bytes(data)))
    data = bytearray(build())
    struct.pack_into(">I", data, 32, 10**6)  # size_dt_strings
    with pytest.raises(DevicetreeError, match=r"strings block .* lies outside"):
        read_dtb(_write(tmp_path, bytes(data)))


def test_unterminated_reservations(tmp_path: Path) -> None:
    data = build(reservations=())
    bad = bytearray(data)
    struct.pack_into(">I", bad, 16, len(bad) - 8)  # reservation block at the very end
    with pytest.raises(DevicetreeError, match="reservation block"):
        read_dtb(_write(tmp_path, bytes(bad)))


def test_unreadable_file(tmp_path: Path) -> None:
    with pytest.raises(DevicetreeError, match="cannot read file"):
        read_dtb(tmp_path / "absent.dtb", root=tmp_path)

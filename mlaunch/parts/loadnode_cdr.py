"""composition_interfaces' LoadNode and UnloadNode as bytes: XCDR1, little-endian.

What rmw_fastrtps (Jazzy) puts in the serialized payload of a service's request and reply
(Fast CDR in XCDRv1 mode): an encapsulation header (``00 01``: CDR little-endian, then the
options, whose two low bits count the padding at the end), then the fields in order, each
aligned on its own size counted from the start of the body (8 bytes for int64, uint64 and
double), strings as a uint32 length that counts the closing NUL, the UTF-8 bytes and the NUL,
sequences as a uint32 count and the items.

LoadNode.Request: package_name, plugin_name, node_name, node_namespace (strings), log_level
(uint8), remap_rules (string[]), parameters and extra_arguments (rcl_interfaces/Parameter[]: a
name and a ParameterValue: type uint8, bool_value, integer_value int64, double_value,
string_value, then byte[], bool[], int64[], double[] and string[] arrays). LoadNode.Response:
success, error_message, full_node_name, unique_id (uint64). UnloadNode: unique_id; success,
error_message.

A value the message cannot carry (an integer outside int64, a string that is not text) raises
``ValueError`` naming the parameter, as building the rosidl message raises in rclpy.
"""

from __future__ import annotations

import struct

from mlaunch.launch_ros.load_request import (
    BOOL,
    BOOL_ARRAY,
    BYTE_ARRAY,
    DOUBLE,
    DOUBLE_ARRAY,
    INTEGER,
    INTEGER_ARRAY,
    STRING,
    STRING_ARRAY,
    LoadRequest,
    TypedParameter,
)
from mlaunch.plan.value import Value

# The encapsulation header of a little-endian CDR body (the options follow: see ``payload``).
CDR_LE = b"\x00\x01"
CDR_BE = b"\x00\x00"
INT64_MIN, INT64_MAX = -(1 << 63), (1 << 63) - 1
UINT64_MAX = (1 << 64) - 1
# A reply larger than this is not a container's answer (a few hundred bytes): refused.
MAX_REPLY = 1 << 20

_U32 = struct.Struct("<I")
_I64 = struct.Struct("<q")
_U64 = struct.Struct("<Q")
_F64 = struct.Struct("<d")


class CdrError(ValueError):
    """Bytes that are not the message they should be (truncated, a bad length, not UTF-8)."""


class Response(Value):
    """A container's answer: LoadNode's fields (UnloadNode's: success and error_message)."""

    _fields = ("success", "error_message", "full_node_name", "unique_id")
    __slots__ = _fields

    def __init__(
        self, success: bool, error_message: str, full_node_name: str = "", unique_id: int = 0
    ) -> None:
        self.success = success
        self.error_message = error_message
        self.full_node_name = full_node_name
        self.unique_id = unique_id


class _Out:
    """An XCDR1 little-endian body being written."""

    __slots__ = ("buf",)

    def __init__(self) -> None:
        self.buf = bytearray()

    def align(self, size: int) -> None:
        pad = -len(self.buf) % size
        if pad:
            self.buf += bytes(pad)

    def u8(self, value: int) -> None:
        self.buf.append(value)

    def u32(self, value: int) -> None:
        self.align(4)
        self.buf += _U32.pack(value)

    def i64(self, value: int) -> None:
        self.align(8)
        self.buf += _I64.pack(value)

    def u64(self, value: int) -> None:
        self.align(8)
        self.buf += _U64.pack(value)

    def f64(self, value: float) -> None:
        self.align(8)
        self.buf += _F64.pack(value)

    def string(self, value: str) -> None:
        data = value.encode("utf-8")
        self.u32(len(data) + 1)
        self.buf += data
        self.buf.append(0)

    def strings(self, values: tuple[str, ...] | list[str]) -> None:
        self.u32(len(values))
        for value in values:
            self.string(value)


def payload(body: bytes | bytearray) -> bytes:
    """The serialized payload of ``body``: the encapsulation header, the body, padded to 4."""
    pad = -len(body) % 4
    return CDR_LE + bytes((0, pad)) + bytes(body) + bytes(pad)


def _int(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{what}: {value!r} is not an integer")
    if not INT64_MIN <= value <= INT64_MAX:
        raise ValueError(f"{what}: {value} is outside int64 [{INT64_MIN}, {INT64_MAX}]")
    return value


def _float(value: object, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{what}: {value!r} is not a number")
    return float(value)


def _byte(value: object, what: str) -> int:
    if isinstance(value, bytes) and len(value) == 1:
        return value[0]
    if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 255:
        return value
    raise ValueError(f"{what}: {value!r} is not a byte")


def _parameter(out: _Out, parameter: TypedParameter) -> None:
    """One rcl_interfaces/Parameter: the fields of its type set, the others zero or empty."""
    kind, value = parameter.type, parameter.value
    what = f"parameter {parameter.name!r}"
    out.string(parameter.name)
    out.u8(kind)
    out.u8(1 if kind == BOOL and value else 0)
    out.i64(_int(value, what) if kind == INTEGER else 0)
    out.f64(_float(value, what) if kind == DOUBLE else 0.0)
    if kind == STRING and not isinstance(value, str):
        raise ValueError(f"{what}: {value!r} is not a string")
    out.string(value if kind == STRING else "")
    items = list(value) if kind >= BYTE_ARRAY else []
    out.u32(len(items) if kind == BYTE_ARRAY else 0)
    if kind == BYTE_ARRAY:
        out.buf += bytes(_byte(v, what) for v in items)
    out.u32(len(items) if kind == BOOL_ARRAY else 0)
    if kind == BOOL_ARRAY:
        out.buf += bytes(1 if v else 0 for v in items)
    out.u32(len(items) if kind == INTEGER_ARRAY else 0)
    if kind == INTEGER_ARRAY:
        for v in items:
            out.i64(_int(v, what))
    out.u32(len(items) if kind == DOUBLE_ARRAY else 0)
    if kind == DOUBLE_ARRAY:
        for v in items:
            out.f64(_float(v, what))
    if kind == STRING_ARRAY:
        if not all(isinstance(v, str) for v in items):
            raise ValueError(f"{what}: {items!r} is not a list of strings")
        out.strings(items)
    else:
        out.u32(0)


def load_request(request: LoadRequest) -> bytes:
    """The serialized payload of ``request`` (LoadNode.Request)."""
    out = _Out()
    try:
        out.string(request.package_name)
        out.string(request.plugin_name)
        out.string(request.node_name)
        out.string(request.node_namespace)
        out.u8(request.log_level & 0xFF)
        out.strings(request.remap_rules)
        for parameters in (request.parameters, request.extra_arguments):
            out.u32(len(parameters))
            for parameter in parameters:
                _parameter(out, parameter)
    except UnicodeEncodeError as e:
        raise ValueError(f"a string of the request is not text: {e}") from None
    return payload(out.buf)


def unload_request(unique_id: int) -> bytes:
    """The serialized payload of UnloadNode.Request."""
    if not 0 <= unique_id <= UINT64_MAX:
        raise ValueError(f"unique_id {unique_id} is outside uint64")
    out = _Out()
    out.u64(unique_id)
    return payload(out.buf)


class _In:
    """An XCDR1 body being read (either endianness); every read is bounded by the data."""

    __slots__ = ("data", "end", "little", "pos")

    def __init__(self, data: bytes, little: bool) -> None:
        self.data = data
        self.pos = 0
        self.end = len(data)
        self.little = little

    def _take(self, size: int, align: int) -> int:
        self.pos += -self.pos % align
        start = self.pos
        if start + size > self.end:
            raise CdrError(f"truncated: {size} bytes wanted at {start} of {self.end}")
        self.pos = start + size
        return start

    def u8(self) -> int:
        return self.data[self._take(1, 1)]

    def u32(self) -> int:
        start = self._take(4, 4)
        return int.from_bytes(self.data[start : start + 4], "little" if self.little else "big")

    def u64(self) -> int:
        start = self._take(8, 8)
        return int.from_bytes(self.data[start : start + 8], "little" if self.little else "big")

    def string(self) -> str:
        size = self.u32()
        if size == 0:  # some writers send an empty string as no bytes at all
            return ""
        start = self._take(size, 1)
        raw = self.data[start : start + size - 1]
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError as e:
            raise CdrError(f"a string that is not UTF-8: {e}") from None


def _body(data: bytes) -> _In:
    if len(data) < 4 or len(data) > MAX_REPLY:
        raise CdrError(f"a payload of {len(data)} bytes")
    head = data[:2]
    if head not in (CDR_LE, CDR_BE):
        raise CdrError(f"encapsulation {head.hex()} is not plain CDR")
    return _In(data[4:], head == CDR_LE)


def load_response(data: bytes) -> Response:
    """LoadNode.Response from its serialized payload (CdrError when it is not one)."""
    body = _body(data)
    success = body.u8() != 0
    error = body.string()
    name = body.string()
    return Response(success, error, name, body.u64())


def unload_response(data: bytes) -> Response:
    """UnloadNode.Response from its serialized payload (CdrError when it is not one)."""
    body = _body(data)
    success = body.u8() != 0
    return Response(success, body.string())

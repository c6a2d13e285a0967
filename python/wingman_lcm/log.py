# SPDX-License-Identifier: MIT
"""LCM log files (the format of lcm-logger, lcm::LogFile and the Wingman recorder).

Each event is a 28-byte big-endian header -- sync word 0xEDA1DA01, event number (int64),
timestamp in microseconds (int64), channel length (int32), data length (int32) -- followed by
the channel name and the encoded message.
"""
import collections
import os
import struct

SYNC_WORD = 0xEDA1DA01
_HEADER = struct.Struct(">IqqII")
HEADER_SIZE = _HEADER.size  # 28
MAX_CHANNEL_LENGTH = 1 << 16  # longer than any sane channel name: a corrupt header

LogEvent = collections.namedtuple("LogEvent", "eventnum timestamp channel data offset")
LogEvent.__doc__ = """One log event: its number, timestamp (microseconds), channel (str), encoded message
(bytes) and the byte offset of its header in the file."""


class LogFormatError(ValueError):
    """A log that is not a well-formed LCM log: the message names the file and the byte offset."""

    def __init__(self, path, offset, what):
        super().__init__("%s: byte %d: %s" % (path, offset, what))
        self.path = path
        self.offset = offset
        self.what = what


def read_log(path):
    """Yields every LogEvent of the LCM log at ``path``, in file order.

    Stops with LogFormatError at the first bad sync word or truncated event (no resynchronisation).
    """
    path = os.fspath(path)
    with open(path, "rb") as f:
        offset = 0
        while True:
            header = f.read(HEADER_SIZE)
            if not header:
                return
            if len(header) < HEADER_SIZE:
                raise LogFormatError(path, offset, "truncated event: header has %d of %d bytes"
                                     % (len(header), HEADER_SIZE))
            sync, eventnum, timestamp, channel_len, data_len = _HEADER.unpack(header)
            if sync != SYNC_WORD:
                raise LogFormatError(path, offset, "bad sync word 0x%08X (expected 0x%08X)" % (sync, SYNC_WORD))
            if channel_len == 0 or channel_len > MAX_CHANNEL_LENGTH or data_len >= 1 << 31:
                raise LogFormatError(path, offset, "corrupt event header: channel length %d, data length %d"
                                     % (channel_len, data_len))
            body = f.read(channel_len + data_len)
            if len(body) < channel_len + data_len:
                raise LogFormatError(path, offset, "truncated event: channel and data need %d bytes, %d left"
                                     % (channel_len + data_len, len(body)))
            try:
                channel = body[:channel_len].decode("utf-8")
            except UnicodeDecodeError:
                raise LogFormatError(path, offset, "channel name is not UTF-8") from None
            yield LogEvent(eventnum, timestamp, channel, body[channel_len:], offset)
            offset += HEADER_SIZE + channel_len + data_len


class LogWriter:
    """Writes an LCM log: ``with LogWriter(path) as log: log.write(channel, data, timestamp)``."""

    def __init__(self, path):
        self._f = open(path, "wb")
        self._eventnum = 0

    def write(self, channel, data, timestamp):
        """Appends one event; ``data`` is an encoded message (``msg.encode()``), ``timestamp`` microseconds."""
        ch = channel.encode("utf-8")
        if not ch:
            raise ValueError("empty channel name")
        self._f.write(_HEADER.pack(SYNC_WORD, self._eventnum, timestamp, len(ch), len(data)))
        self._f.write(ch)
        self._f.write(data)
        self._eventnum += 1

    def close(self):
        self._f.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

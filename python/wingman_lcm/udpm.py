# SPDX-License-Identifier: MIT
"""An LCM ``udpm://`` bus in the standard library: subscribe, and publish.

The wire format is LCM's (lcm/udpm_util.h, lcm/lcm_udpm.c), all fields big-endian:

* small message, one datagram: magic "LC02" (uint32), sequence number (uint32), channel name,
  a NUL byte, the encoded message;
* large message, several datagrams ("fragments"): magic "LC03" (uint32), sequence number
  (uint32), message size (uint32, without the channel), fragment offset in the message (uint32),
  fragment number (uint16), fragments in the message (uint16); fragment 0 carries the channel
  name and a NUL byte before its part of the message.

A datagram that is not LCM's, or a malformed one, is dropped and counted in ``Udpm.stats``.
"""
import collections
import os
import re
import socket
import struct
import time
import urllib.parse

DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=0"
MAGIC_SHORT = 0x4C433032  # "LC02"
MAGIC_LONG = 0x4C433033  # "LC03"
_SHORT = struct.Struct(">II")
_LONG = struct.Struct(">IIIIHH")
SHORT_MESSAGE_MAX_SIZE = 65499  # channel + NUL + message: above this LCM (Linux) fragments
FRAGMENT_MAX_PAYLOAD = 65487
MAX_CHANNEL_LENGTH = 63
MAX_MESSAGE_SIZE = 1 << 28
DEFAULT_RECV_BUF_SIZE = 8 * 1024 * 1024  # asked for; the kernel caps it at net.core.rmem_max

Message = collections.namedtuple("Message", "channel data recv_utime sender")
Message.__doc__ = """One received message: channel (str), encoded message (bytes), receive time
(microseconds since the epoch, the last datagram's) and the sender's (address, port)."""


class UrlError(ValueError):
    """An LCM URL this module does not handle."""


def parse_url(url=None):
    """(group, port, ttl, recv_buf_size or None) of a ``udpm://GROUP:PORT?ttl=N&recv_buf_size=B`` URL.

    ``None`` or "" means $LCM_DEFAULT_URL, else LCM's default (DEFAULT_URL).
    """
    if not url:
        url = os.environ.get("LCM_DEFAULT_URL") or DEFAULT_URL
    u = urllib.parse.urlsplit(url)
    if u.scheme != "udpm":
        raise UrlError("%s: only udpm:// URLs are handled" % url)
    try:
        group = u.hostname or "239.255.76.67"
        port = u.port or 7667
        first = int(socket.inet_aton(group)[0])
    except (OSError, ValueError):
        raise UrlError("%s: bad multicast address or port" % url) from None
    if not 224 <= first <= 239:
        raise UrlError("%s: %s is not a multicast address" % (url, group))
    ttl, recv_buf_size = 0, None
    for key, value in urllib.parse.parse_qsl(u.query, keep_blank_values=True):
        try:
            if key == "ttl":
                ttl = int(value)
                if not 0 <= ttl <= 255:
                    raise ValueError
            elif key == "recv_buf_size":
                recv_buf_size = int(value)
                if recv_buf_size <= 0:
                    raise ValueError
            else:
                raise UrlError("%s: unknown option %s" % (url, key))
        except ValueError:
            raise UrlError("%s: bad value of %s: %r" % (url, key, value)) from None
    return group, port, ttl, recv_buf_size


class _Partial:
    """The fragments of one large message received so far."""

    __slots__ = ("msg_size", "count", "channel", "fragments", "bytes", "last_packet")

    def __init__(self, msg_size, count, now):
        self.msg_size = msg_size
        self.count = count
        self.channel = None
        self.fragments = {}  # fragment number -> (offset, bytes)
        self.bytes = 0
        self.last_packet = now


class Udpm:
    """One LCM udpm bus.

    ``subscribe(regex)`` joins the multicast group (the socket exists from then on: messages sent
    before are not seen); ``receive``/``messages`` return the messages of subscribed channels (LCM
    semantics: the regular expression matches the whole channel name). ``publish`` sends like LCM.
    Not thread-safe; use one Udpm per thread.
    """

    def __init__(self, url=None, max_pending=32, max_pending_bytes=64 << 20, fragment_timeout_s=2.0):
        self.url = url or os.environ.get("LCM_DEFAULT_URL") or DEFAULT_URL
        self.group, self.port, self.ttl, self._recv_buf_request = parse_url(self.url)
        self.max_pending = max_pending
        self.max_pending_bytes = max_pending_bytes
        self.fragment_timeout_s = fragment_timeout_s
        self.recv_buf_size = None  # the kernel's receive buffer once subscribed (what getsockopt reports)
        self._patterns = []
        self._recv = None
        self._send = None
        self._seqno = 0
        self._pending = collections.OrderedDict()  # (sender, seqno) -> _Partial
        self.stats = dict(packets=0, messages=0, fragmented_messages=0, not_subscribed=0, dropped_foreign=0,
                          dropped_malformed=0, dropped_incomplete=0)

    @property
    def dropped(self):
        """Datagrams dropped (not LCM's, malformed) plus large messages that never completed."""
        s = self.stats
        return s["dropped_foreign"] + s["dropped_malformed"] + s["dropped_incomplete"]

    # ---- receiving -----------------------------------------------------------------------------

    def subscribe(self, channel_regex=".*"):
        """Receives the channels whose whole name matches ``channel_regex`` (from now on)."""
        self._patterns.append(re.compile(channel_regex))
        if self._recv is None:
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
            try:
                s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, self._recv_buf_request or DEFAULT_RECV_BUF_SIZE)
                self.recv_buf_size = s.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
                s.bind(("", self.port))
                mreq = socket.inet_aton(self.group) + socket.inet_aton("0.0.0.0")
                s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
            except OSError:
                s.close()
                raise
            self._recv = s

    def receive(self, timeout_s):
        """The next message of a subscribed channel, or None after ``timeout_s`` seconds without one."""
        if self._recv is None:
            raise RuntimeError("receive before subscribe")
        deadline = time.monotonic() + max(0.0, timeout_s)
        self._expire(time.monotonic())
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self._recv.settimeout(left)
            try:
                packet, sender = self._recv.recvfrom(65536)
            except socket.timeout:
                return None
            msg = self._handle_packet(packet, sender)
            if msg is not None:
                return msg

    def messages(self, max_messages, timeout_s):
        """Yields up to ``max_messages`` messages, for at most ``timeout_s`` seconds in all."""
        deadline = time.monotonic() + timeout_s
        for _ in range(max_messages):
            msg = self.receive(deadline - time.monotonic())
            if msg is None:
                return
            yield msg

    def _handle_packet(self, packet, sender):
        """The complete message a datagram makes, or None (a fragment, dropped, not subscribed)."""
        self.stats["packets"] += 1
        now = time.monotonic()
        self._expire(now)
        if len(packet) < _SHORT.size:
            self.stats["dropped_foreign"] += 1
            return None
        magic, seqno = _SHORT.unpack_from(packet)
        if magic == MAGIC_SHORT:
            parsed = self._channel_and_rest(packet, _SHORT.size)
            if parsed is None:
                return None
            channel, data = parsed
        elif magic == MAGIC_LONG:
            done = self._add_fragment(packet, sender, seqno, now)
            if done is None:
                return None
            channel, data = done
            self.stats["fragmented_messages"] += 1
        else:
            self.stats["dropped_foreign"] += 1
            return None
        self.stats["messages"] += 1
        if not any(p.fullmatch(channel) for p in self._patterns):
            self.stats["not_subscribed"] += 1
            return None
        return Message(channel, data, int(time.time() * 1e6), sender)

    def _channel_and_rest(self, packet, start):
        """(channel, bytes after its NUL) or None (counted malformed)."""
        nul = packet.find(b"\0", start, start + MAX_CHANNEL_LENGTH + 1)
        if nul <= start:  # no NUL within the longest channel name, or an empty name
            self.stats["dropped_malformed"] += 1
            return None
        try:
            channel = packet[start:nul].decode("utf-8")
        except UnicodeDecodeError:
            self.stats["dropped_malformed"] += 1
            return None
        return channel, packet[nul + 1:]

    def _add_fragment(self, packet, sender, seqno, now):
        """Adds one LC03 fragment; (channel, message) once the message is complete, else None."""
        if len(packet) < _LONG.size:
            self.stats["dropped_malformed"] += 1
            return None
        _, _, msg_size, offset, number, count = _LONG.unpack_from(packet)
        if count == 0 or number >= count or msg_size > MAX_MESSAGE_SIZE:
            self.stats["dropped_malformed"] += 1
            return None
        channel = None
        if number == 0:
            parsed = self._channel_and_rest(packet, _LONG.size)
            if parsed is None:
                return None
            channel, data = parsed
        else:
            data = packet[_LONG.size:]
        if offset + len(data) > msg_size:
            self.stats["dropped_malformed"] += 1
            return None
        key = (sender, seqno)
        part = self._pending.get(key)
        if part is not None and (part.msg_size != msg_size or part.count != count):
            del self._pending[key]  # a stale message with the same number: give it up
            self.stats["dropped_incomplete"] += 1
            part = None
        if part is None:
            part = _Partial(msg_size, count, now)
            self._pending[key] = part
        if number in part.fragments:
            self.stats["dropped_malformed"] += 1  # a duplicate
            return None
        part.fragments[number] = (offset, data)
        part.bytes += len(data)
        part.last_packet = now
        if channel is not None:
            part.channel = channel
        if len(part.fragments) < count:
            self._limit_pending()
            return None
        del self._pending[key]
        if part.bytes != part.msg_size:
            self.stats["dropped_malformed"] += 1  # fragments that do not tile the message
            return None
        buf = bytearray(part.msg_size)
        for off, chunk in part.fragments.values():
            buf[off:off + len(chunk)] = chunk
        return part.channel, bytes(buf)

    def _expire(self, now):
        """Gives up the large messages without a fragment for fragment_timeout_s."""
        if not self._pending:
            return
        stale = [k for k, p in self._pending.items() if now - p.last_packet > self.fragment_timeout_s]
        for k in stale:
            del self._pending[k]
            self.stats["dropped_incomplete"] += 1

    def _limit_pending(self):
        while self._pending and (len(self._pending) > self.max_pending
                                 or sum(p.bytes for p in self._pending.values()) > self.max_pending_bytes):
            self._pending.popitem(last=False)  # the oldest
            self.stats["dropped_incomplete"] += 1

    # ---- publishing ----------------------------------------------------------------------------

    def publish(self, channel, data):
        """Sends one encoded message (``msg.encode()``) on ``channel`` as LCM does: one datagram up to
        65499 bytes of channel, NUL and message, else fragments of 65487 bytes."""
        ch = channel.encode("utf-8")
        if not ch or len(ch) > MAX_CHANNEL_LENGTH or b"\0" in ch:
            raise ValueError("channel name must have 1 to %d bytes and no NUL: %r" % (MAX_CHANNEL_LENGTH, channel))
        data = bytes(data)
        if self._send is None:
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
            s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.ttl)
            s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            self._send = s
        dest = (self.group, self.port)
        head = ch + b"\0"
        if len(head) + len(data) <= SHORT_MESSAGE_MAX_SIZE:
            self._send.sendto(_SHORT.pack(MAGIC_SHORT, self._seqno) + head + data, dest)
        else:
            if len(data) > MAX_MESSAGE_SIZE:
                raise ValueError("message of %d bytes: LCM's limit is %d" % (len(data), MAX_MESSAGE_SIZE))
            total = len(head) + len(data)
            count = -(-total // FRAGMENT_MAX_PAYLOAD)
            first = FRAGMENT_MAX_PAYLOAD - len(head)
            self._send.sendto(_LONG.pack(MAGIC_LONG, self._seqno, len(data), 0, 0, count) + head + data[:first], dest)
            offset = first
            for number in range(1, count):
                chunk = data[offset:offset + FRAGMENT_MAX_PAYLOAD]
                self._send.sendto(_LONG.pack(MAGIC_LONG, self._seqno, len(data), offset, number, count) + chunk, dest)
                offset += len(chunk)
        self._seqno = (self._seqno + 1) & 0xFFFFFFFF

    # ---- life ----------------------------------------------------------------------------------

    def close(self):
        for s in (self._recv, self._send):
            if s is not None:
                s.close()
        self._recv = self._send = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

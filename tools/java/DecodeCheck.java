// SPDX-License-Identifier: MIT
// Decodes every message of an LCM log the way lcm-spy does (class by fingerprint from the classpath); reports per channel.

import java.io.DataInput;
import java.io.EOFException;
import java.io.IOException;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import java.util.Map;
import java.util.TreeMap;

import lcm.lcm.LCMDataInputStream;
import lcm.logging.Log;
import lcm.spy.LCMTypeDatabase;

/**
 * Usage: java -cp LCM_JAR:TYPES_JAR:DIR_OF_THIS_CLASS DecodeCheck LOG [CHANNEL...]
 *
 * <p>Reads LOG with lcm.logging.Log. For each message, as lcm.spy.Spy's subscriber does: reads the
 * 8-byte fingerprint at the start, looks the class up in lcm.spy.LCMTypeDatabase (which scans the
 * classpath for LCM types), and decodes the message with the class's DataInput constructor. Prints
 * one line per channel: channel, type name ("-" when none), message count, and OK or UNDECODABLE
 * (with the reason). Exits 0 when every channel decodes and every CHANNEL named on the command line
 * is in the log, 1 otherwise, 2 on a usage or I/O error.
 */
public final class DecodeCheck {
  /** What one channel of the log looked like. */
  private static final class ChannelResult {
    String typeName = "-";
    long count = 0;
    long failures = 0;
    String firstError = null;
  }

  private DecodeCheck() {}

  public static void main(String[] args) {
    if (args.length < 1 || args[0].equals("-h") || args[0].equals("--help")) {
      System.err.println("usage: DecodeCheck LOG [CHANNEL...]   (put lcm.jar and the types jar on the classpath)");
      System.exit(args.length < 1 ? 2 : 0);
    }
    final String logPath = args[0];
    final List<String> expected = new ArrayList<>(Arrays.asList(args).subList(1, args.length));

    // Prints "Found N LCM types" to stdout, as in lcm-spy.
    final LCMTypeDatabase types = new LCMTypeDatabase();
    final Map<String, ChannelResult> channels = new TreeMap<>();

    try {
      final Log log = new Log(logPath, "r");
      try {
        while (true) {
          final Log.Event ev;
          try {
            ev = log.readNext();
          } catch (EOFException eof) {
            break;
          }
          final ChannelResult r = channels.computeIfAbsent(ev.channel, k -> new ChannelResult());
          r.count++;
          final String err = decode(types, ev.data, r);
          if (err != null) {
            r.failures++;
            if (r.firstError == null) r.firstError = err;
          }
        }
      } finally {
        log.close();
      }
    } catch (IOException e) {
      System.err.println("DecodeCheck: cannot read LCM log " + logPath + ": " + e);
      System.exit(2);
    }

    boolean ok = true;
    for (Map.Entry<String, ChannelResult> e : channels.entrySet()) {
      final ChannelResult r = e.getValue();
      final boolean channelOk = r.failures == 0;
      ok &= channelOk;
      System.out.println(String.format("%-20s %-28s %6d %s", e.getKey(), r.typeName, r.count,
          channelOk ? "OK" : "UNDECODABLE (" + r.failures + " of " + r.count + ": " + r.firstError + ")"));
    }
    for (String channel : expected) {
      if (!channels.containsKey(channel)) {
        ok = false;
        System.out.println(String.format("%-20s %-28s %6d %s", channel, "-", 0, "MISSING (not in the log)"));
      }
    }
    System.out.println(ok ? "DecodeCheck: every channel decodes" : "DecodeCheck: FAILED");
    System.exit(ok ? 0 : 1);
  }

  /** Decodes one message as lcm-spy does; returns null on success, else why it failed. */
  private static String decode(LCMTypeDatabase types, byte[] data, ChannelResult r) {
    if (data.length < 8) return "shorter than a fingerprint (" + data.length + " bytes)";
    final LCMDataInputStream in = new LCMDataInputStream(data);
    final long fingerprint;
    try {
      fingerprint = in.readLong();
      in.reset();
    } catch (IOException e) {
      return "cannot read the fingerprint: " + e;
    }
    final Class<?> cls = types.getClassByFingerprint(fingerprint);
    if (cls == null) return String.format("no class on the classpath has fingerprint 0x%016x", fingerprint);
    r.typeName = cls.getName();
    try {
      cls.getConstructor(DataInput.class).newInstance(in);
    } catch (ReflectiveOperationException e) {
      final Throwable cause = e.getCause() != null ? e.getCause() : e;
      return cls.getName() + " does not decode it: " + cause;
    }
    return null;
  }
}

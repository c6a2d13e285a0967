// SPDX-License-Identifier: MIT
// Listens to an LCM bus with Java LCM, as lcm-spy does (its receive path and classpath), and reports per channel.

import java.io.DataInput;
import java.io.IOException;
import java.util.Map;
import java.util.TreeMap;

import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;
import lcm.spy.LCMTypeDatabase;

/**
 * Usage: java -cp LCM_JAR:TYPES_JAR:DIR_OF_THIS_CLASS BusCheck URL SECONDS
 *
 * <p>Subscribes to every channel of URL with lcm.lcm.LCM (the receiver lcm-spy uses: Java LCM 1.3.1 ignores
 * recv_buf_size), for SECONDS, and decodes each message by its fingerprint with lcm.spy.LCMTypeDatabase. Prints one
 * line per channel: channel, type ("-" when none), messages received, messages decoded, mean bytes. Exits 0, or 2 on
 * a usage error or a URL Java LCM refuses.
 */
public final class BusCheck {
  private static final class ChannelResult {
    String typeName = "-";
    long count = 0;
    long decoded = 0;
    long bytes = 0;
  }

  private BusCheck() {}

  public static void main(String[] args) throws InterruptedException {
    if (args.length != 2) {
      System.err.println("usage: BusCheck URL SECONDS   (put lcm.jar and the types jar on the classpath)");
      System.exit(2);
    }
    final double seconds = Double.parseDouble(args[1]);
    final LCMTypeDatabase types = new LCMTypeDatabase();
    final Map<String, ChannelResult> channels = new TreeMap<>();
    final LCM lcm;
    try {
      lcm = new LCM(args[0]);
    } catch (IOException e) {
      System.err.println("BusCheck: cannot open " + args[0] + ": " + e);
      System.exit(2);
      return;
    }
    lcm.subscribeAll(new LCMSubscriber() {
      @Override
      public void messageReceived(LCM l, String channel, LCMDataInputStream in) {
        synchronized (channels) {
          final ChannelResult r = channels.computeIfAbsent(channel, k -> new ChannelResult());
          r.count++;
          r.bytes += in.available();
          try {
            final long fingerprint = in.readLong();
            in.reset();
            final Class<?> cls = types.getClassByFingerprint(fingerprint);
            if (cls == null) return;
            r.typeName = cls.getName();
            cls.getConstructor(DataInput.class).newInstance(in);
            r.decoded++;
          } catch (IOException | ReflectiveOperationException e) {
            // counted as received, not decoded
          }
        }
      }
    });
    System.out.println("BusCheck: listening");
    System.out.flush();
    Thread.sleep((long) (seconds * 1000));
    lcm.close();
    synchronized (channels) {
      for (Map.Entry<String, ChannelResult> e : channels.entrySet()) {
        final ChannelResult r = e.getValue();
        System.out.println(String.format("%-20s %-28s %6d %6d %9d", e.getKey(), r.typeName, r.count, r.decoded,
            r.count > 0 ? r.bytes / r.count : 0));
      }
    }
    System.exit(0);
  }
}

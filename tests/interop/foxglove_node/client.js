// A Foxglove WebSocket client as a Foxglove user's tools would run it, for
// tests/interop/test_foxglove_live.py: @foxglove/ws-protocol's FoxgloveClient on a `ws`
// socket, the messages decoded from CDR with the channel's advertised ros2msg schema by
// @foxglove/rosmsg (parse) and @foxglove/rosmsg2-serialization (MessageReader), the
// packages Foxglove's own app decodes ROS 2 data with. Nothing here comes from tactsense.
//
// usage: node client.js URL SUBPROTOCOL COUNTS TIMEOUT_MS [timing]
// COUNTS is JSON, {"topic": messages wanted, ...}. Subscribes to those topics as they are
// advertised, prints one JSON object per line on stdout ("open", "serverInfo",
// "advertise" with each channel, "subscribed", then each "message": topic, timestamp
// [ns] as a string, the raw bytes in base64 and the decoded message), and exits 0 once
// every topic has had its count; 2 on a timeout (after TIMEOUT_MS). With "timing" each
// message is still decoded, but its line has only the topic, the timestamp and
// "received_ms", the Unix time [ms] of the callback (benchmarks/bench_foxglove_live.py).
"use strict";

const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const WebSocket = require("ws");

const [url, subprotocol, countsText, timeoutText, mode] = process.argv.slice(2);
const timing = mode === "timing";
const counts = JSON.parse(countsText);

function print(object) {
  process.stdout.write(
    JSON.stringify(object, (_key, value) => {
      if (typeof value === "bigint") return value.toString();
      if (ArrayBuffer.isView(value) && !(value instanceof DataView)) return Array.from(value);
      return value;
    }) + "\n",
  );
}

const ws = new WebSocket(url, [subprotocol]);
const client = new FoxgloveClient({ ws });
const bySubscription = new Map(); // subscription id -> {topic, reader}
const received = new Map(); // topic -> messages so far

function finish(code) {
  process.stdout.write("", () => process.exit(code)); // after every line is out
}

setTimeout(() => {
  print({ op: "timeout", received: Object.fromEntries(received) });
  finish(2);
}, Number(timeoutText));

client.on("open", () => print({ op: "open", protocol: ws.protocol }));
client.on("error", (error) => print({ op: "error", error: String(error) }));
client.on("serverInfo", (info) => print(info));
client.on("advertise", (channels) => {
  for (const channel of channels) {
    print({ op: "advertise", channel });
    if (!(channel.topic in counts)) continue;
    const definitions = parse(channel.schema, { ros2: true });
    const reader = new MessageReader(definitions);
    const id = client.subscribe(channel.id);
    bySubscription.set(id, { topic: channel.topic, reader });
    received.set(channel.topic, 0);
    print({ op: "subscribed", topic: channel.topic, subscriptionId: id });
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const entry = bySubscription.get(subscriptionId);
  if (entry === undefined) return;
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  const n = received.get(entry.topic);
  if (n >= counts[entry.topic]) return;
  received.set(entry.topic, n + 1);
  if (timing) {
    const receivedMs = performance.timeOrigin + performance.now();
    entry.reader.readMessage(bytes);
    print({ op: "message", topic: entry.topic, timestamp, received_ms: receivedMs });
  } else {
    print({
      op: "message",
      topic: entry.topic,
      timestamp,
      data: Buffer.from(bytes).toString("base64"),
      decoded: entry.reader.readMessage(bytes),
    });
  }
  const done = Object.keys(counts).every((topic) => (received.get(topic) ?? 0) >= counts[topic]);
  if (done) {
    client.close();
    finish(0);
  }
});

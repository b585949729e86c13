// Independent reader of a rovo ROS 2 bag: Foxglove's @mcap/core (indexed and streaming readers,
// CRCs validated) and @foxglove/rosmsg + @foxglove/rosmsg2-serialization (the ros2msg schemas parsed
// and the CDR messages decoded by that code alone). Run by ros2_bag_test.cc.
//
// Usage: node ros2_bag_check.mjs NODE_MODULES_DIR BAG.mcap OUT_DIR
// Writes OUT_DIR/check.json: per-topic counts from the index, the statistics and a linear scan; the
// first decoded message of each topic (Image data as OUT_DIR/<topic>.bin, the rest as JSON).
import { createRequire } from "node:module";
import { open, readFile, writeFile } from "node:fs/promises";
import path from "node:path";

const [modules, bagPath, outDir] = process.argv.slice(2);
const require = createRequire(path.join(modules, "package.json"));
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

function toPlain(value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) return Array.from(value);
  if (Array.isArray(value)) return value.map(toPlain);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, toPlain(v)]));
  }
  return value;
}

const handle = await open(bagPath, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, size) => {
    const buffer = new Uint8Array(Number(size));
    await handle.read(buffer, 0, Number(size), Number(offset));
    return buffer;
  },
};
const reader = await McapIndexedReader.Initialize({ readable });
const readers = new Map();
const result = {
  profile: reader.header.profile,
  indexed_counts: {},
  statistics_counts: {},
  stream_counts: {},
  schemas: {},
  first: {},
  in_order: true,
};
for (const [id, channel] of reader.channelsById) {
  const schema = reader.schemasById.get(channel.schemaId);
  result.schemas[channel.topic] = schema.name;
  if (schema.encoding !== "ros2msg" || channel.messageEncoding !== "cdr") {
    throw new Error(`${channel.topic}: schema encoding ${schema.encoding}, message encoding ${channel.messageEncoding}`);
  }
  readers.set(id, new MessageReader(parse(new TextDecoder().decode(schema.data), { ros2: true })));
  const count = reader.statistics?.channelMessageCounts.get(id);
  result.statistics_counts[channel.topic] = count === undefined ? -1 : Number(count);
}
let last = -1n;
for await (const message of reader.readMessages({ validateCrcs: true })) {
  const channel = reader.channelsById.get(message.channelId);
  result.indexed_counts[channel.topic] = (result.indexed_counts[channel.topic] ?? 0) + 1;
  if (message.logTime < last) result.in_order = false;
  last = message.logTime;
  if (result.first[channel.topic] !== undefined) continue;
  const decoded = readers.get(message.channelId).readMessage(message.data);
  decoded.log_time_ns = message.logTime;
  if (decoded.data instanceof Uint8Array && decoded.encoding !== undefined) {
    const file = path.join(outDir, channel.topic.replaceAll("/", "_") + ".bin");
    await writeFile(file, decoded.data);
    decoded.data = { file, length: decoded.data.length };
  }
  result.first[channel.topic] = toPlain(decoded);
}
await handle.close();

// A second, linear read of the whole file with CRC checks (data section, chunks, summary).
const stream = new McapStreamReader({ validateCrcs: true });
stream.append(await readFile(bagPath));
const topics = new Map();
let record;
while ((record = stream.nextRecord()) !== undefined) {
  if (record.type === "Channel") topics.set(record.id, record.topic);
  if (record.type === "Message") {
    const topic = topics.get(record.channelId);
    result.stream_counts[topic] = (result.stream_counts[topic] ?? 0) + 1;
  }
}
if (!stream.done()) throw new Error("the stream reader did not reach the footer");
await writeFile(path.join(outDir, "check.json"), JSON.stringify(result, null, 1));

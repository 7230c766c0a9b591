// Records what a Foxglove WebSocket server sends, with Foxglove's own protocol client
// (@foxglove/ws-protocol): connects (retrying until the server is up), subscribes to every
// advertised channel, and when the server closes the connection (or after TIMEOUT_S) prints one
// JSON object: per topic, the schema name, the number of messages and their decoded JSON
// (poses in full; point clouds as their point count, pose and keyframe id).
// Usage: node foxglove-check.mjs ws://HOST:PORT [TIMEOUT_S]
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;  // a CommonJS package

const url = process.argv[2];
const timeoutS = Number(process.argv[3] ?? 60);
const start = Date.now();
const topics = {};
const channels = new Map();
const decoder = new TextDecoder();

function summarize(topic, message) {
  if (message.data === undefined) return message;
  const bytes = Buffer.from(message.data, "base64").length;
  return { timestamp: message.timestamp, pose: message.pose, keyframe: message.keyframe,
           points: bytes / message.point_stride };
}

let finished = false;
function finish(reason) {
  if (finished) return;
  finished = true;
  // Exit once the output is written: a pipe takes it asynchronously.
  process.stdout.write(JSON.stringify({ reason, topics }) + "\n", () => process.exit(0));
}

function connect() {
  const client = new FoxgloveClient({
    ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
  });
  let opened = false;
  client.on("open", () => { opened = true; });
  client.on("advertise", (advertised) => {
    for (const channel of advertised) {
      const id = client.subscribe(channel.id);
      channels.set(id, channel);
      topics[channel.topic] = { schemaName: channel.schemaName, encoding: channel.encoding, messages: [] };
    }
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const channel = channels.get(subscriptionId);
    const message = JSON.parse(decoder.decode(data));
    topics[channel.topic].messages.push({ receiveTimestamp: String(timestamp), ...summarize(channel.topic, message) });
  });
  client.on("close", () => {
    if (opened) finish("closed by the server");
    else if ((Date.now() - start) / 1000 < timeoutS) setTimeout(connect, 200);
    else finish("never connected");
  });
  client.on("error", () => {});
}

setTimeout(() => finish("timeout"), timeoutS * 1000);
connect();

// SPDX-License-Identifier: MIT
// The independent side of tests/mavlink/test_node_crosscheck.cpp: node-mavlink encodes the cases the C++ test
// lists and decodes the C++ codec's frames (through its stream splitter, as a reader of a serial port would).
// Input (file argument), one case per line:
//   <name> <v1|v2> <sysid> <compid> <seq> <hex of the C++ frame> <field>=<value> ...
// (arrays comma-separated, 64-bit integers in decimal). Output, one line per case, in order:
//   <index> <hex of node-mavlink's frame> <field>=<value> ...   (fields as node-mavlink decoded the C++ frame)
// or "<index> ERROR <reason>". Exits 0 once every case is answered.
'use strict';
const fs = require('fs');
const { PassThrough } = require('stream');
const mavlink = require('node-mavlink');

const REGISTRY = { ...mavlink.minimal.REGISTRY, ...mavlink.common.REGISTRY };
const BY_NAME = {};
for (const clazz of Object.values(REGISTRY)) BY_NAME[clazz.MSG_NAME] = clazz;

const is64 = (type) => type.startsWith('int64_t') || type.startsWith('uint64_t');
const parseScalar = (type, text) => (is64(type) ? BigInt(text) : Number(text));
const show = (v) => (Array.isArray(v) ? v.map((x) => x.toString()).join(',') : v.toString());

const lines = fs.readFileSync(process.argv[2], 'utf8').split('\n').filter((l) => l.trim().length > 0);
const cases = lines.map((line) => {
  const [name, version, sysid, compid, seq, hex, ...fields] = line.split(' ');
  const values = {};
  for (const kv of fields) {
    const eq = kv.indexOf('=');
    values[kv.slice(0, eq)] = kv.slice(eq + 1);
  }
  return { name, version, sysid: Number(sysid), compid: Number(compid), seq: Number(seq), hex, values };
});

const out = new Array(cases.length);
// node-mavlink's encoding of each case.
cases.forEach((c, i) => {
  const clazz = BY_NAME[c.name];
  if (!clazz) {
    out[i] = `${i} ERROR node-mavlink has no ${c.name}`;
    return;
  }
  const msg = new clazz();
  for (const f of clazz.FIELDS) {
    const text = c.values[f.source];
    if (text === undefined) {
      out[i] = `${i} ERROR the case has no field ${f.source}`;
      return;
    }
    const base = f.type.replace('[]', '');
    msg[f.name] = f.length > 0 ? text.split(',').map((t) => parseScalar(base, t)) : parseScalar(base, text);
  }
  const protocol =
    c.version === 'v1' ? new mavlink.MavLinkProtocolV1(c.sysid, c.compid) : new mavlink.MavLinkProtocolV2(c.sysid, c.compid);
  c.nodeHex = protocol.serialize(msg, c.seq).toString('hex');
});

// The C++ frames, all in one stream, through node-mavlink's splitter and parser.
const input = new PassThrough();
const decoded = [];
const reader = input.pipe(new mavlink.MavLinkPacketSplitter()).pipe(new mavlink.MavLinkPacketParser());
reader.on('data', (packet) => decoded.push(packet));
reader.on('end', () => {
  let next = 0;
  cases.forEach((c, i) => {
    if (out[i]) return;
    const packet = decoded[next++];
    if (!packet) {
      out[i] = `${i} ERROR node-mavlink's splitter found no frame for this case`;
      return;
    }
    const clazz = REGISTRY[packet.header.msgid];
    if (!clazz || clazz.MSG_NAME !== c.name) {
      out[i] = `${i} ERROR node-mavlink decoded message id ${packet.header.msgid}, not ${c.name}`;
      return;
    }
    const data = packet.protocol.data(packet.payload, clazz);
    const fields = clazz.FIELDS.map((f) => `${f.source}=${show(data[f.name])}`);
    const header = `seq=${packet.header.seq} sysid=${packet.header.sysid} compid=${packet.header.compid}`;
    out[i] = `${i} ${c.nodeHex} ${header} ${fields.join(' ')}`;
  });
  process.stdout.write(out.join('\n') + '\n');
});
for (const c of cases) if (!out[cases.indexOf(c)]) input.write(Buffer.from(c.hex, 'hex'));
input.end();

// Reads a LAS file with copc.js (an LAS 1.2/1.4 reader written by the PDAL developers) and prints
// what it finds as JSON: the header, the VLRs (with a WKT record's text), the extra bytes'
// descriptions and the first points (with their extra fields).
// taiga's tests compare this with what taiga wrote, so that taiga's LAS writer is checked by a
// reader it shares no code with. Usage: node las-check.mjs FILE [MAX_POINTS]
import { readFileSync } from 'node:fs';
import copc from 'copc';

const { Las } = copc;
const [path, maxPointsText = '10'] = process.argv.slice(2);
const bytes = new Uint8Array(readFileSync(path));
const header = Las.Header.parse(bytes.subarray(0, 375));
const vlrs = await Las.Vlr.walk(async (begin, end) => bytes.subarray(begin, end), header);
const vlrInfo = [];
let extraBytes = [];
for (const vlr of vlrs) {
  if (vlr.userId === 'LASF_Spec' && vlr.recordId === 4) {
    extraBytes = Las.ExtraBytes.parse(bytes.subarray(vlr.contentOffset, vlr.contentOffset + vlr.contentLength));
  }
  const info = { userId: vlr.userId, recordId: vlr.recordId, length: vlr.contentLength };
  if (vlr.userId === 'LASF_Projection' && vlr.recordId === 2112) {
    const content = bytes.subarray(vlr.contentOffset, vlr.contentOffset + vlr.contentLength);
    info.wkt = new TextDecoder().decode(content).replace(/\0+$/, '');
  }
  vlrInfo.push(info);
}
const count = Number(header.pointCount);
const data = bytes.subarray(header.pointDataOffset, header.pointDataOffset + count * header.pointDataRecordLength);
const view = Las.View.create(data, header, extraBytes);
const names = ['X', 'Y', 'Z', 'Intensity', 'ReturnNumber', 'NumberOfReturns', 'Classification', 'UserData',
  'PointSourceId', 'GpsTime', ...extraBytes.map((eb) => eb.name)];
const get = Object.fromEntries(names.map((n) => [n, view.getter(n)]));
const points = [];
for (let i = 0; i < Math.min(count, Number(maxPointsText)); ++i) {
  points.push(Object.fromEntries(names.map((n) => [n, get[n](i)])));
}
console.log(JSON.stringify({
  version: `${header.majorVersion}.${header.minorVersion}`,
  pointDataRecordFormat: header.pointDataRecordFormat,
  pointDataRecordLength: header.pointDataRecordLength,
  pointCount: count,
  globalEncoding: header.globalEncoding,
  scale: header.scale, offset: header.offset, min: header.min, max: header.max,
  vlrs: vlrInfo, extraBytes, points,
}, null, 1));

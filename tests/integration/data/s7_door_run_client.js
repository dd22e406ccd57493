// nodes7 0.3.18, unmodified, against the s7_door of a running `pbvbus run` (tests/integration/
// s7_door_run_test.cpp). Prints one `key=value` line per result (value as JSON text), then
// `done=true`, and exits.
//
//   NODE_PATH=<dir with nodes7> node s7_door_run_client.js rw PORT SLOT BASE FLAG IO
//     rack 0 / SLOT: writes DB1 bytes BASE..BASE+3, INT at BASE+4, REAL at BASE+8, MB FLAG,
//     IB IO and QB IO, reads them back in one readAllItems (nodes7 joins the DB1 items into one
//     request item: same area and DB, gaps <= its maxGap of 5), then reads DB9 (missing).
//   NODE_PATH=... node s7_door_run_client.js h PORT FT_SLOT STD_SLOT
//     two connections to an H-system: FT_SLOT (a fault-tolerant connection) and STD_SLOT (a
//     standard one). Writes DB1,INT0 = 4321 over the fault-tolerant one, then reads DB1,INT0
//     over both every 100 ms until the standard one has failed and the fault-tolerant one has
//     read five more times. nodes7 is not silent here: its own log lines (`[time NAME] ...`,
//     NAME = "ftN" or "stdN", N the attempt) show the disconnect it saw.
//
// Every wait is bounded (a connection: 20 s of retries; the whole script: 40 s), only as a guard.
'use strict';
const nodes7 = require('nodes7');

const out = (k, v) => process.stdout.write(k + '=' + JSON.stringify(v) + '\n');
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

function fail(why) {
  out('error', why);
  process.exit(1);
}

// One nodes7 connection attempt: resolves with the connection or the error.
// `timeout` is nodes7's for the connection and for each job.
function connectOnce(port, slot, name, silent, timeout) {
  return new Promise((resolve) => {
    const conn = new nodes7({ silent });
    conn.initiateConnection({ host: '127.0.0.1', port, rack: 0, slot, timeout, connection_name: name },
                            (err) => resolve({ conn, err }));
  });
}

// Connects, retrying every 300 ms (the door refuses until the route's target accepts
// connections, e.g. an H connection before Redundant; an MPI route waits for the ring). Each
// attempt is a nodes7 connection of its own, named NAME + attempt ("ft1", "ft2", ...), so that
// its log lines can be told apart; NAME_name says which one connected.
async function connect(port, slot, name, silent, timeout) {
  const end = Date.now() + 20000;
  let attempts = 0;
  for (;;) {
    ++attempts;
    const { conn, err } = await connectOnce(port, slot, name + attempts, silent, timeout);
    if (typeof err === 'undefined') {
      out(name + '_attempts', attempts);
      out(name + '_name', name + attempts);
      return conn;
    }
    conn.dropConnection(() => {});
    if (Date.now() > end) fail(name + ': no connection within 20 s: ' + String(err));
    await sleep(300);
  }
}

function read(conn, items) {
  return new Promise((resolve) => {
    conn.removeItems();
    conn.addItems(items);
    conn.readAllItems((anythingBad, values) => resolve({ anythingBad, values }));
  });
}

function write(conn, items, values) {
  return new Promise((resolve) => conn.writeItems(items, values, (anythingBad) => resolve(anythingBad)));
}

function drop(conn) {
  return new Promise((resolve) => conn.dropConnection(() => resolve()));
}

async function rw(port, slot, base, flag, io) {
  const conn = await connect(port, slot, 'rw', true, 8000);
  const db = (t, off) => 'DB1,' + t + (base + off);
  const items = [db('B', 0) + '.4', db('INT', 4), db('REAL', 8), 'MB' + flag, 'IB' + io, 'QB' + io];
  const writeBad = await write(conn, items, [[0x11, 0x22, 0x33, 0x44], -1234 - base, 2.5 + base,
                                             0x2A + flag, 0x81, 0x42 + io]);
  out('write_bad', writeBad);
  const back = await read(conn, items);
  out('back_bad', back.anythingBad);
  for (const k of items) out(k, back.values[k]);
  const missing = await read(conn, ['DB9,B0']);
  out('missing_bad', missing.anythingBad);
  out('DB9,B0', missing.values['DB9,B0']);
  await drop(conn);
}

async function h(port, ftSlot, stdSlot) {
  // 2 s: a job the door leaves unanswered (the standard route after its CPU failed: the door
  // sends a DR instead) comes back bad from nodes7 only when this timeout runs out.
  const ft = await connect(port, ftSlot, 'ft', false, 2000);
  out('ft_write_bad', await write(ft, ['DB1,INT0'], [4321]));
  const std = await connect(port, stdSlot, 'std', false, 2000);
  const item = ['DB1,INT0'];
  const ftValues = {}, stdValues = {};
  let ftBad = 0, ftAfter = 0, stdGood = 0, stdLost = false;
  const end = Date.now() + 20000;
  while (!(stdLost && ftAfter >= 5)) {
    if (Date.now() > end) break;
    const [a, b] = await Promise.all([read(ft, item), stdLost ? null : read(std, item)]);
    if (a.anythingBad) ++ftBad;
    else if (stdLost) ++ftAfter;
    ftValues[String(a.values['DB1,INT0'])] = true;
    if (b !== null) {
      if (b.anythingBad) {
        stdLost = true;
        out('std_lost_after_good_reads', stdGood);
        out('std_lost_value', b.values['DB1,INT0']);
        std.dropConnection(() => {});  // no reconnection attempts by nodes7 from here
      } else {
        ++stdGood;
        stdValues[String(b.values['DB1,INT0'])] = true;
      }
    }
    await sleep(100);
  }
  out('ft_values', Object.keys(ftValues));
  out('ft_bad', ftBad);
  out('ft_reads_after_std_lost', ftAfter);
  out('std_values', Object.keys(stdValues));
  out('std_lost', stdLost);
  out('ft_dropping', true);  // nodes7's log lines of ft after this are about our own drop
  await drop(ft);
}

const [mode, portText, ...rest] = process.argv.slice(2);
const port = parseInt(portText, 10);
const n = rest.map((x) => parseInt(x, 10));
const job = mode === 'rw' ? rw(port, n[0], n[1], n[2], n[3]) : mode === 'h' ? h(port, n[0], n[1]) : null;
if (job === null) fail('usage: rw PORT SLOT BASE FLAG IO | h PORT FT_SLOT STD_SLOT');
job.then(() => {
  out('done', true);
  process.exit(0);
}).catch((e) => fail(String(e && e.stack ? e.stack : e)));
setTimeout(() => fail('no result within 40 s'), 40000).unref();

// The released Toxiproxy Node client (npm toxiproxy-node-client), unmodified,
// against hil's control API: `hil proxy --api` in front of `hil mock logi`.
// It creates a proxy, measures round trips of real LOGI frames through it,
// adds and removes a latency toxic and measures the delay it adds, uses
// getVersion, getAll, populate and reset, and disables the proxy: the open
// connection is closed and new ones are refused.
//
// Usage: node toxiproxy_node_test.js HIL_BINARY
// (NODE_PATH names the node_modules folder that holds the client.)
'use strict';

const {spawn} = require('child_process');
const net = require('net');
const {Toxiproxy, ToxiproxyError} = require('toxiproxy-node-client');

const hil = process.argv[2];
if (!hil) {
  console.error('usage: node toxiproxy_node_test.js HIL_BINARY');
  process.exit(2);
}

const LATENCY_MS = 200;
const ROUND_TRIPS = 10;
const children = [];
let failures = 0;

function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
  if (!ok) failures += 1;
}

// Starts hil with args, resolves with the first match of pattern in its output.
function startHil(args, pattern) {
  return new Promise((resolve, reject) => {
    const child = spawn(hil, args, {stdio: ['ignore', 'pipe', 'pipe']});
    children.push(child);
    let output = '';
    const timer = setTimeout(
        () => reject(new Error(`hil ${args.join(' ')}: no start line in 15 s:\n${output}`)), 15000);
    const onData = (data) => {
      output += data.toString();
      const match = output.match(pattern);
      if (match) {
        clearTimeout(timer);
        resolve({child, match});
      }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', onData);
    child.on('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`hil ${args.join(' ')} exited with ${code}:\n${output}`));
    });
  });
}

function stopHil(child) {
  return new Promise((resolve) => {
    if (child.exitCode !== null || child.signalCode !== null) return resolve(child.exitCode);
    const kill = setTimeout(() => child.kill('SIGKILL'), 5000);
    child.removeAllListeners('exit');
    child.on('exit', (code) => {
      clearTimeout(kill);
      resolve(code);
    });
    child.kill('SIGTERM');
  });
}

function logiFrame(payload) {
  const head = 'LOGI:' + payload;
  let sum = 0;
  for (const byte of Buffer.from(head, 'ascii'))
    sum = (sum + byte) & 0xff;
  return Buffer.from(`${head}:${sum.toString(16).toUpperCase().padStart(2, '0')}#`, 'ascii');
}

function hostPort(address) {
  const colon = address.lastIndexOf(':');
  return {host: address.slice(0, colon) || '127.0.0.1', port: Number(address.slice(colon + 1))};
}

// A TCP connection that hands out the payloads of the LOGI frames it reads.
class LogiConnection {
  constructor(address) {
    this.address = address;
    this.buffer = '';
    this.waiters = [];
    this.closed = false;
    this.closedWaiters = [];
  }

  open() {
    return new Promise((resolve, reject) => {
      this.socket = net.connect(hostPort(this.address), () => {
        this.socket.setNoDelay(true);
        resolve(this);
      });
      this.socket.once('error', reject);
      this.socket.on('data', (data) => this.onData(data));
      this.socket.on('close', () => {
        this.closed = true;
        for (const waiter of this.closedWaiters)
          waiter();
      });
      this.socket.on('error', () => {});
    });
  }

  onData(data) {
    this.buffer += data.toString('latin1');
    for (;;) {
      const start = this.buffer.indexOf('LOGI:');
      const end = start < 0 ? -1 : this.buffer.indexOf('#', start);
      if (end < 0) return;
      const frame = this.buffer.slice(start + 5, end);
      this.buffer = this.buffer.slice(end + 1);
      const payload = frame.slice(0, frame.lastIndexOf(':'));
      const waiter = this.waiters.find((w) => payload.startsWith(w.prefix));
      if (waiter) {
        this.waiters.splice(this.waiters.indexOf(waiter), 1);
        waiter.resolve(payload);
      }
    }
  }

  // Sends payload and resolves with the answer that starts with prefix.
  request(payload, prefix, timeoutMs = 5000) {
    return new Promise((resolve, reject) => {
      const timer = setTimeout(
          () => reject(new Error(`no ${prefix} answer to ${payload} in ${timeoutMs} ms`)),
          timeoutMs);
      this.waiters.push({
        prefix,
        resolve: (answer) => {
          clearTimeout(timer);
          resolve(answer);
        }
      });
      this.socket.write(logiFrame(payload));
    });
  }

  // Milliseconds of ROUND_TRIPS round trips of SP and its FB:SP answer.
  async roundTripsMs() {
    const times = [];
    for (let i = 0; i < ROUND_TRIPS; i += 1) {
      const start = process.hrtime.bigint();
      const answer = await this.request('SP:050', 'FB:SP:');
      times.push(Number(process.hrtime.bigint() - start) / 1e6);
      if (answer !== 'FB:SP:1') throw new Error(`SP:050 was answered ${answer}`);
    }
    return times;
  }

  waitClosed(timeoutMs) {
    if (this.closed) return Promise.resolve(true);
    return new Promise((resolve) => {
      const timer = setTimeout(() => resolve(false), timeoutMs);
      this.closedWaiters.push(() => {
        clearTimeout(timer);
        resolve(true);
      });
    });
  }

  close() { this.socket.destroy(); }
}

function median(values) {
  const sorted = [...values].sort((a, b) => a - b);
  const mid = Math.floor(sorted.length / 2);
  return sorted.length % 2 ? sorted[mid] : (sorted[mid - 1] + sorted[mid]) / 2;
}

function describe(times) {
  return `median ${median(times).toFixed(1)} ms, min ${Math.min(...times).toFixed(1)}, max ${
      Math.max(...times).toFixed(1)}`;
}

function connectRefused(address) {
  return new Promise((resolve) => {
    const socket = net.connect(hostPort(address));
    socket.once('connect', () => {
      socket.destroy();
      resolve(null);
    });
    socket.once('error', (error) => resolve(error.code));
  });
}

async function main() {
  // Two cars: a car serves one client at a time, and the populated proxy
  // below talks to the second while the first proxy's connection is open.
  const mock = await startHil(
      ['mock', 'logi', '--port', '0', '--count', '2', '-q'],
      /car0 connect to tcp:\/\/(\S+)[^]*car1 connect to tcp:\/\/(\S+)/);
  const [upstream, upstream2] = [mock.match[1], mock.match[2]];
  const proxyServer =
      await startHil(['proxy', '--api', '127.0.0.1:0'], /control API at (http:\/\/\S+)/);
  const apiUrl = proxyServer.match[1].replace(/[/,]+$/, '');
  console.log(`hil mock logi at ${upstream} and ${upstream2}, control API at ${apiUrl}`);

  const toxiproxy = new Toxiproxy(apiUrl);
  const version = await toxiproxy.getVersion();
  console.log(`getVersion: ${version.trim()}`);
  check(/^hil /.test(version), 'getVersion names hil');

  const proxy = await toxiproxy.createProxy({name: 'logi', listen: '127.0.0.1:0', upstream});
  console.log(`createProxy: ${proxy.name} listen ${proxy.listen} upstream ${
      proxy.upstream} enabled ${proxy.enabled}`);
  check(
      proxy.name === 'logi' && proxy.upstream === upstream && proxy.enabled === true,
      'createProxy answers the proxy as declared, enabled');
  check(
      /^127\.0\.0\.1:[1-9][0-9]*$/.test(proxy.listen),
      'createProxy with port 0 answers the real port');

  const conn = await new LogiConnection(proxy.listen).open();
  const baseline = await conn.roundTripsMs();
  console.log(`round trip SP:050 -> FB:SP:1 through the proxy: ${describe(baseline)}`);
  check(median(baseline) < 100, 'round trips without toxics are fast (< 100 ms)');

  const toxic = await proxy.addToxic({
    name: 'slow_answers',
    type: 'latency',
    stream: 'downstream',
    toxicity: 1,
    attributes: {latency: LATENCY_MS, jitter: 0},
  });
  check(
      toxic.name === 'slow_answers' && toxic.type === 'latency' && toxic.stream === 'downstream',
      'addToxic answers the toxic');
  const slow = await conn.roundTripsMs();
  const addedMs = median(slow) - median(baseline);
  console.log(`with a ${LATENCY_MS} ms downstream latency toxic: ${describe(slow)}; added ${
      addedMs.toFixed(1)} ms`);
  check(
      addedMs >= LATENCY_MS - 10 && addedMs < LATENCY_MS + 400,
      `the latency toxic adds ${LATENCY_MS} ms to each answer (>= ${LATENCY_MS - 10}, < ${
          LATENCY_MS + 400})`);
  const fetched = await proxy.getToxic('slow_answers');
  check(
      fetched.attributes && fetched.attributes.latency === LATENCY_MS,
      'getToxic reads the latency back');

  await toxic.remove();
  const after = await conn.roundTripsMs();
  console.log(`after removing the toxic: ${describe(after)}`);
  check(
      median(after) < median(baseline) + 50,
      'without the toxic the round trips are back near the baseline');

  const all = await toxiproxy.getAll();
  check(Object.keys(all).join(',') === 'logi', 'getAll lists the one proxy');
  const populated =
      await toxiproxy.populate([{name: 'second', listen: '127.0.0.1:0', upstream: upstream2}]);
  check(
      populated.second && /^127\.0\.0\.1:[1-9]/.test(populated.second.listen),
      'populate creates a second proxy');
  check(
      Object.keys(await toxiproxy.getAll()).sort().join(',') === 'logi,second',
      'getAll lists both');
  const second = await new LogiConnection(populated.second.listen).open();
  check(
      (await second.request('GS:001', 'FB:GS:')) === 'FB:GS:1',
      'the populated proxy carries frames');
  second.close();
  await populated.second.remove();

  await proxy.addToxic(
      {name: 'cut', type: 'timeout', stream: 'upstream', toxicity: 1, attributes: {timeout: 0}});
  await toxiproxy.reset();
  let gone = false;
  try {
    await proxy.getToxic('cut');
  } catch (error) {
    gone = error instanceof ToxiproxyError;
  }
  check(gone, 'reset removes the toxics made through the API (getToxic fails)');
  check(
      (await conn.request('SP:050', 'FB:SP:')) === 'FB:SP:1',
      'after reset the open connection still carries frames');

  const disabled = await proxy.update({...proxy.toJson(), enabled: false});
  check(disabled.enabled === false, 'update {enabled:false} answers the proxy disabled');
  const closed = await conn.waitClosed(2000);
  check(closed, 'disabling the proxy closes the open connection');
  const refusal = await connectRefused(proxy.listen);
  console.log(`a new connection to the disabled proxy: ${refusal || 'accepted'}`);
  check(refusal === 'ECONNREFUSED', 'a disabled proxy refuses new connections');

  const enabled = await proxy.update({...proxy.toJson(), enabled: true});
  check(enabled.enabled === true, 'update {enabled:true} enables it again');
  const again = await new LogiConnection(enabled.listen).open();
  check(
      (await again.request('SP:050', 'FB:SP:')) === 'FB:SP:1',
      'the re-enabled proxy carries frames');
  again.close();

  await proxy.remove();
  check(Object.keys(await toxiproxy.getAll()).length === 0, 'remove deletes the proxy');

  const proxyCode = await stopHil(proxyServer.child);
  const mockCode = await stopHil(mock.child);
  check(
      proxyCode === 0 && mockCode === 0,
      `hil proxy and hil mock stop cleanly on SIGTERM (${proxyCode}, ${mockCode})`);
}

const watchdog = setTimeout(() => {
  console.log('FAIL the test did not finish in 90 s');
  for (const child of children)
    child.kill('SIGKILL');
  process.exit(1);
}, 90000);

main()
    .catch((error) => {
      console.log(`FAIL ${error.stack || error}`);
      failures += 1;
    })
    .finally(async () => {
      clearTimeout(watchdog);
      for (const child of children)
        await stopHil(child);
      console.log(failures ? `${failures} check(s) failed` : 'every check passed');
      process.exit(failures ? 1 : 0);
    });

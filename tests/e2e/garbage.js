'use strict'
// Sends an infiniterra server what a real player never would: bytes that are not the
// Minecraft protocol, an HTTP request, and a login from the wrong Minecraft version. Prints
// one JSON line saying how the server answered each. Driven by tests/server_e2e.rs.
//
// usage: node garbage.js PORT [--timeout SECONDS]

const net = require('net')
const mc = require('minecraft-protocol')

const port = Number(process.argv[2])
const timeoutIndex = process.argv.indexOf('--timeout')
const timeoutMs = (timeoutIndex > 0 ? Number(process.argv[timeoutIndex + 1]) : 20) * 1000

// Writes `bytes` on a fresh connection; resolves when the server closes it (or the timeout).
function closedAfter (bytes) {
  return new Promise(resolve => {
    const started = Date.now()
    const socket = net.connect(port, '127.0.0.1', () => socket.write(bytes))
    const timer = setTimeout(() => { socket.destroy(); resolve({ closed: false }) }, timeoutMs)
    socket.on('error', () => {})
    socket.on('close', () => { clearTimeout(timer); resolve({ closed: true, ms: Date.now() - started }) })
    socket.resume() // discard anything the server says
  })
}

// Logs in as a 1.19.4 client (protocol 762); resolves with the server's disconnect reason.
function wrongVersion () {
  return new Promise(resolve => {
    const client = mc.createClient({ host: '127.0.0.1', port, username: 'old_client', version: '1.19.4', auth: 'offline', hideErrors: true })
    const result = { kicked: false, reason: null, reached_play: false }
    const timer = setTimeout(() => { client.end(); resolve(result) }, timeoutMs)
    client.on('disconnect', packet => { result.kicked = true; result.reason = packet.reason })
    client.on('kick_disconnect', packet => { result.kicked = true; result.reason = packet.reason })
    client.on('login', () => { result.reached_play = true })
    client.on('error', () => {})
    client.on('end', () => { clearTimeout(timer); resolve(result) })
  })
}

async function main () {
  if (!Number.isInteger(port)) throw new Error('usage: node garbage.js PORT')
  const report = {
    // Five bytes with the continuation bit set: a VarInt length that never ends.
    varint_overflow: await closedAfter(Buffer.from([0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x01])),
    http_request: await closedAfter(Buffer.from('GET / HTTP/1.1\r\nHost: localhost\r\n\r\n')),
    random_bytes: await closedAfter(Buffer.from(Array.from({ length: 512 }, (_, i) => (i * 7919 + 13) & 0xff))),
    wrong_version: await wrongVersion()
  }
  process.stdout.write(JSON.stringify(report) + '\n')
  process.exit(0)
}

main().catch(error => {
  process.stdout.write(JSON.stringify({ error: String(error) }) + '\n')
  process.exit(1)
})

'use strict'
// Many players join and leave, round after round. Driven by tests/server_e2e.rs.
//
// usage: node churn.js PORT [--bots N] [--rounds R] [--view CHUNKS] [--stagger MS] [--timeout SECONDS]
//
// Each round starts N bots (one every --stagger ms), waits until every one of them has spawned
// and received at least one chunk, then has them all quit and waits until every connection
// has closed. Prints one JSON line; exit code 0 with {"ok":true,...}, 1 with {"ok":false,...}.

const mineflayer = require('mineflayer')

function parseArgs (argv) {
  const args = { port: Number(argv[0]), bots: 20, rounds: 3, view: 2, stagger: 50, timeout: 120 }
  for (let i = 1; i < argv.length; i += 2) {
    const [key, value] = [argv[i], Number(argv[i + 1])]
    if (key === '--bots') args.bots = value
    else if (key === '--rounds') args.rounds = value
    else if (key === '--view') args.view = value
    else if (key === '--stagger') args.stagger = value
    else if (key === '--timeout') args.timeout = value
    else throw new Error(`unknown argument ${key}`)
  }
  if (!Number.isInteger(args.port)) throw new Error('usage: node churn.js PORT [options]')
  return args
}

// One bot: resolves when it has spawned and holds a chunk; rejects on a kick or an error.
function join (args, name) {
  return new Promise((resolve, reject) => {
    const bot = mineflayer.createBot({
      host: '127.0.0.1',
      port: args.port,
      username: name,
      version: '1.20.1',
      auth: 'offline',
      viewDistance: args.view,
      hideErrors: true
    })
    let chunks = 0
    let spawned = false
    const ready = () => { if (spawned && chunks > 0) resolve(bot) }
    bot._client.on('map_chunk', () => { chunks++; ready() })
    bot.once('spawn', () => { spawned = true; ready() })
    bot.once('kicked', reason => reject(new Error(`${name} kicked: ${JSON.stringify(reason)}`)))
    bot.once('error', error => reject(new Error(`${name}: ${error && error.message ? error.message : error}`)))
    bot.once('end', reason => reject(new Error(`${name} disconnected before spawning: ${reason}`)))
  })
}

function leave (bot) {
  return new Promise(resolve => {
    bot.removeAllListeners('end')
    bot.once('end', resolve)
    bot.quit()
  })
}

async function main () {
  const args = parseArgs(process.argv.slice(2))
  setTimeout(() => {
    process.stdout.write(JSON.stringify({ ok: false, error: `timed out after ${args.timeout} s` }) + '\n')
    process.exit(1)
  }, args.timeout * 1000).unref()
  const started = Date.now()
  const rounds = []
  for (let r = 0; r < args.rounds; r++) {
    const t = Date.now()
    const joining = []
    for (let i = 0; i < args.bots; i++) {
      joining.push(join(args, `churn_${r}_${i}`))
      await new Promise(resolve => setTimeout(resolve, args.stagger)) // paces the joins
    }
    const bots = await Promise.all(joining)
    const joinedMs = Date.now() - t
    await Promise.all(bots.map(leave))
    rounds.push({ joined_ms: joinedMs, round_ms: Date.now() - t })
  }
  process.stdout.write(JSON.stringify({ ok: true, rounds, total_ms: Date.now() - started }) + '\n')
  process.exit(0)
}

main().catch(error => {
  process.stdout.write(JSON.stringify({ ok: false, error: String(error && error.message ? error.message : error) }) + '\n')
  process.exit(1)
})

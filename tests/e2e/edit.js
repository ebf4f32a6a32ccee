'use strict'
// Two players and one edit: an observer joins first; a builder joins, breaks the block at
// --break and places --block on top of the block at --place-on (creative mode, the item set
// in its hotbar the way a creative client does). The observer must see both changes arrive
// as the server's block updates. Prints one JSON line on stdout. Driven by tests/server_e2e.rs.
//
// usage: node edit.js PORT --break X,Y,Z --place-on X,Y,Z [--block NAME] [--timeout SECONDS]
//
// Exit code 0 with {"ok":true,...}; 1 with {"ok":false,"error":...} on a kick, an error or
// the timeout. Every wait is for an event or a condition, bounded by the timeout.

const { createBot } = require('./bot')
const { Vec3 } = require('vec3')

function parseArgs (argv) {
  const args = { port: Number(argv[0]), block: 'gold_block', timeout: 120 }
  const point = value => new Vec3(...value.split(',').map(Number))
  for (let i = 1; i < argv.length; i += 2) {
    const [key, value] = [argv[i], argv[i + 1]]
    if (key === '--break') args.break = point(value)
    else if (key === '--place-on') args.placeOn = point(value)
    else if (key === '--block') args.block = value
    else if (key === '--timeout') args.timeout = Number(value)
    else throw new Error(`unknown argument ${key}`)
  }
  if (!Number.isInteger(args.port) || !args.break || !args.placeOn) {
    throw new Error('usage: node edit.js PORT --break X,Y,Z --place-on X,Y,Z [options]')
  }
  return args
}

function main () {
  const args = parseArgs(process.argv.slice(2))
  const report = { ok: false }
  const bots = []
  let done = false
  const finish = code => {
    done = true
    process.stdout.write(JSON.stringify(report) + '\n')
    for (const bot of bots) {
      try { bot.quit() } catch (_) {}
    }
    // Give the quit packets a moment to leave, without waiting on the server.
    setTimeout(() => process.exit(code), 200).unref()
  }
  const fail = error => {
    if (done) return
    report.error = String(error && error.stack ? error.stack : error)
    finish(1)
  }
  setTimeout(() => fail(`timed out after ${args.timeout} s`), args.timeout * 1000).unref()

  const join = name => new Promise(resolve => {
    const bot = createBot(args.port, name, 4)
    bots.push(bot)
    bot.on('kicked', reason => fail(`${name} kicked: ${JSON.stringify(reason)}`))
    bot.on('error', error => fail(`${name}: ${error && error.message ? error.message : error}`))
    bot.on('end', reason => fail(`${name}'s connection ended: ${reason}`))
    bot.once('spawn', () => resolve(bot))
  })
  // Resolves with the block's name once `want(name)` holds for the block at `pos` as `bot`
  // knows it: now, or at a later chunk load or block update.
  const until = (bot, pos, want) => new Promise(resolve => {
    const check = () => {
      const block = bot.blockAt(pos)
      if (block === null || !want(block.name)) return false
      bot.off(`blockUpdate:${pos}`, check)
      bot.off('chunkColumnLoad', check)
      resolve(block.name)
      return true
    }
    if (check()) return
    bot.on(`blockUpdate:${pos}`, check)
    bot.on('chunkColumnLoad', check)
  })
  const any = () => true
  const placeAt = args.placeOn.offset(0, 1, 0)

  const run = async () => {
    const observer = await join('observer')
    report.before = {
      broken: await until(observer, args.break, any),
      place_on: await until(observer, args.placeOn, any),
      placed: await until(observer, placeAt, any)
    }
    const sawBreak = until(observer, args.break, name => name === 'air')
    const sawPlace = until(observer, placeAt, name => name === args.block)

    const builder = await join('builder')
    report.game_mode = builder.game.gameMode
    await until(builder, args.break, any)
    await until(builder, args.placeOn, any)
    const Item = require('prismarine-item')(builder.registry)
    const item = builder.registry.itemsByName[args.block]
    if (!item) throw new Error(`no item called ${args.block}`)
    await builder.creative.setInventorySlot(36, new Item(item.id, 1))
    builder.setQuickBarSlot(0)
    await builder.dig(builder.blockAt(args.break), true)
    await builder.placeBlock(builder.blockAt(args.placeOn), new Vec3(0, 1, 0))
    report.observer_saw = { broken: await sawBreak, placed: await sawPlace }
    report.ok = true
    finish(0)
  }
  run().catch(fail)
}

main()

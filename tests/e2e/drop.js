'use strict'
// A survival player digs the block under its feet by hand, falls into the hole and picks up
// what the block dropped. Prints one JSON line on stdout: the block dug, the item entity the
// server showed, and the player's inventory after the pickup. Driven by tests/server_e2e.rs.
//
// usage: node drop.js PORT [--timeout SECONDS]
//
// Exit code 0 with {"ok":true,...}; 1 with {"ok":false,"error":...} on a kick, an error or
// the timeout. Every wait is for an event or a condition, bounded by the timeout.

const { createBot } = require('./bot')

function main () {
  const argv = process.argv.slice(2)
  const args = { port: Number(argv[0]), timeout: 120 }
  for (let i = 1; i < argv.length; i += 2) {
    if (argv[i] === '--timeout') args.timeout = Number(argv[i + 1])
    else throw new Error(`unknown argument ${argv[i]}`)
  }
  const report = { ok: false }
  let bot = null
  let done = false
  const finish = code => {
    done = true
    process.stdout.write(JSON.stringify(report) + '\n')
    try { bot.quit() } catch (_) {}
    setTimeout(() => process.exit(code), 200).unref()
  }
  const fail = error => {
    if (done) return
    if (bot && bot.entity) {
      const p = bot.entity.position
      report.position_at_failure = { x: p.x, y: p.y, z: p.z, on_ground: bot.entity.onGround }
      report.items_at_failure = items()
    }
    report.error = String(error && error.stack ? error.stack : error)
    finish(1)
  }
  setTimeout(() => fail(`timed out after ${args.timeout} s`), args.timeout * 1000).unref()

  bot = createBot(args.port, 'digger', 4)
  // No falling before the ground has arrived: a loaded machine may send the player's
  // position well before the chunk under it, and a client simulating its fall through the
  // missing chunk ends up inside the ground.
  bot.physicsEnabled = false
  bot.on('kicked', reason => fail(`kicked: ${JSON.stringify(reason)}`))
  bot.on('error', error => fail(error && error.message ? error.message : error))
  bot.on('end', reason => fail(`connection ended: ${reason}`))

  // Resolves once the chunk under the player is loaded and the player stands on it.
  const grounded = () => new Promise(resolve => {
    const check = () => {
      // The block whose top the feet rest on (a hair below them: mud and soul sand are
      // lower than a whole block).
      const below = bot.blockAt(bot.entity.position.offset(0, -0.01, 0))
      if (below === null || !bot.entity.onGround) return
      bot.off('physicsTick', check)
      resolve(below)
    }
    bot.on('physicsTick', check)
  })
  const items = () => bot.inventory.items().map(i => ({ name: i.name, count: i.count }))

  // Resolves once the chunk holding the player has arrived.
  const chunkLoaded = () => new Promise(resolve => {
    const check = () => {
      if (bot.blockAt(bot.entity.position) === null) return false
      bot.off('chunkColumnLoad', check)
      resolve()
      return true
    }
    if (!check()) bot.on('chunkColumnLoad', check)
  })

  bot.once('spawn', async () => {
    try {
      report.game_mode = bot.game.gameMode
      await chunkLoaded()
      bot.physicsEnabled = true
      const block = await grounded()
      report.dug = { name: block.name, x: block.position.x, y: block.position.y, z: block.position.z }
      report.before = items()
      const seen = new Promise(resolve => {
        const onSpawn = entity => {
          if (entity.name !== 'item') return
          bot.off('entitySpawn', onSpawn)
          const p = entity.position
          resolve({ x: p.x, y: p.y, z: p.z })
        }
        bot.on('entitySpawn', onSpawn)
      })
      const collected = new Promise(resolve => {
        const onCollect = (collector, collected) => {
          if (collector !== bot.entity) return
          bot.off('playerCollect', onCollect)
          resolve(collected.id)
        }
        bot.on('playerCollect', onCollect)
      })
      await bot.dig(block, true)
      report.drop_at = await seen
      await collected
      // The inventory update follows the pickup animation in the same tick; wait for it.
      await new Promise(resolve => {
        const check = () => {
          if (bot.inventory.items().length === 0) return false
          bot.inventory.off('updateSlot', check)
          resolve()
          return true
        }
        if (!check()) bot.inventory.on('updateSlot', check)
      })
      report.after = items()
      report.ok = true
      finish(0)
    } catch (e) {
      fail(e)
    }
  })
}

main()

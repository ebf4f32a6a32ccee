//! Item drops: what a block broken in survival drops, lying as an item in the world, and
//! players picking drops up.
//!
//! Vanilla decides drops with loot tables, which valence does not have; the common cases of
//! a generated world are written here by hand: stone gives cobblestone, ores their raw metal,
//! coal, diamonds or dust (in vanilla's counts), grass blocks dirt, glass and ice nothing,
//! leaves now and then a sapling, and everything else itself. Blocks that need a pickaxe drop
//! nothing without one of the tier vanilla asks for (iron ore a stone pickaxe, diamond ore an
//! iron one). Counts that vary are drawn from the block's position, so a drop does not depend
//! on timing. Drops are not saved: like vanilla's, they are short-lived (five minutes).

use valence::entity::item::{ItemEntityBundle, Stack};
use valence::entity::EntityId;
use valence::inventory::HeldItem;
use valence::layer::Layer;
use valence::prelude::*;
use valence::protocol::packets::play::ItemPickupAnimationS2c;
use valence::protocol::{VarInt, WritePacket};

use crate::chunkgen::unit3;

/// Salt of the draws that vary a drop's count (the world's seed plays no part).
const DROP_SALT: u64 = 0xD209_5EED;
/// Ticks before a drop can be picked up (vanilla's pickup delay, half a second).
const PICKUP_DELAY: u32 = 10;
/// Ticks a drop lies before it vanishes (vanilla's five minutes).
const LIFETIME: u32 = 6000;
/// How far a player reaches for drops beyond its own box, blocks: vanilla's (1, ½, 1).
const REACH: (f64, f64, f64) = (1.0, 0.5, 1.0);
/// A player's box: half its width and its height, blocks.
const PLAYER: (f64, f64) = (0.3, 1.8);
/// A drop's box: half its width and its height, blocks.
const ITEM: (f64, f64) = (0.125, 0.25);

/// An item lying in the world, and for how many ticks it has.
#[derive(Component, Debug, Default)]
pub struct Drop {
    age: u32,
}

/// Adds picking up and expiring drops.
pub fn build(app: &mut App) {
    app.add_systems(Update, pick_up);
}

/// What breaking `block` at `pos` with `tool` in the main hand drops in survival, as (item,
/// count); `None` for nothing.
pub fn drop_of(block: BlockState, tool: Option<ItemKind>, pos: BlockPos) -> Option<(ItemKind, u8)> {
    let name = block.to_kind().to_str();
    if needs_pickaxe(name) && pickaxe_tier(tool) < tier_needed(name) {
        return None;
    }
    // A draw in [0, 1) fixed by the block and its place.
    let draw = f64::from(unit3(DROP_SALT, u64::from(block.to_raw()), pos.x.into(), pos.y.into(), pos.z.into()));
    let between = |lo: u8, hi: u8| lo + (draw * f64::from(hi - lo + 1)) as u8;
    let item = |n: &str| ItemKind::from_str(n);
    let ore = name.strip_prefix("deepslate_").unwrap_or(name);
    let (kind, count) = match ore {
        "stone" => (item("cobblestone")?, 1),
        "deepslate" => (item("cobbled_deepslate")?, 1),
        "grass_block" | "podzol" | "mycelium" | "dirt_path" | "farmland" => (item("dirt")?, 1),
        "coal_ore" => (item("coal")?, 1),
        "iron_ore" => (item("raw_iron")?, 1),
        "gold_ore" => (item("raw_gold")?, 1),
        "copper_ore" => (item("raw_copper")?, between(2, 5)),
        "diamond_ore" => (item("diamond")?, 1),
        "emerald_ore" => (item("emerald")?, 1),
        "lapis_ore" => (item("lapis_lazuli")?, between(4, 9)),
        "redstone_ore" => (item("redstone")?, between(4, 5)),
        // Gravel gives flint one time in ten.
        "gravel" if draw < 0.1 => (item("flint")?, 1),
        "clay" => (item("clay_ball")?, 4),
        "snow_block" => (item("snowball")?, 4),
        "snow" => (item("snowball")?, 1),
        "glowstone" => (item("glowstone_dust")?, between(2, 4)),
        "melon" => (item("melon_slice")?, between(3, 7)),
        "bookshelf" => (item("book")?, 3),
        "dead_bush" => (item("stick")?, between(0, 2)),
        "cocoa" => (item("cocoa_beans")?, between(2, 3)),
        "sweet_berry_bush" => (item("sweet_berries")?, between(2, 3)),
        // Vines need shears (not in play yet).
        "vine" => return None,
        // A huge mushroom's cap gives a mushroom now and then (vanilla: 0–2, mostly none);
        // its stem gives nothing without silk touch.
        "brown_mushroom_block" | "red_mushroom_block" => {
            let small = name.trim_end_matches("_block");
            (item(small)?, between(0, 8).saturating_sub(6))
        }
        "mushroom_stem" => return None,
        // Grass gives seeds one time in eight.
        "grass" | "tall_grass" | "fern" | "large_fern" if draw < 0.125 => (item("wheat_seeds")?, 1),
        "grass" | "tall_grass" | "fern" | "large_fern" | "ice" | "packed_ice" | "blue_ice" | "glass" | "glass_pane"
        | "budding_amethyst" => return None,
        _ if name.ends_with("_leaves") => {
            // A sapling one time in twenty; the rest nothing (no shears in play yet).
            let sapling = match name {
                "mangrove_leaves" => "mangrove_propagule".to_string(),
                "azalea_leaves" => "azalea".to_string(),
                "flowering_azalea_leaves" => "flowering_azalea".to_string(),
                _ => name.replace("_leaves", "_sapling"),
            };
            return (draw < 0.05).then(|| item(&sapling).map(|k| (k, 1))).flatten();
        }
        _ if name.ends_with("_glass") || name.ends_with("_glass_pane") => return None,
        _ => (block.to_kind().to_item_kind(), 1),
    };
    (kind != ItemKind::Air && count > 0).then_some((kind, count))
}

/// Whether vanilla drops nothing for `name` broken without a pickaxe.
fn needs_pickaxe(name: &str) -> bool {
    name.ends_with("_ore")
        || (name.ends_with("stone") && name != "glowstone")
        || name.ends_with("deepslate")
        || name.ends_with("bricks")
        || name.ends_with("terracotta")
        || name.ends_with("_concrete")
        || matches!(
            name,
            "andesite"
                | "diorite"
                | "granite"
                | "tuff"
                | "calcite"
                | "dripstone_block"
                | "pointed_dripstone"
                | "obsidian"
                | "basalt"
                | "smooth_basalt"
                | "netherrack"
                | "magma_block"
                | "amethyst_block"
                | "prismarine"
                | "iron_block"
                | "gold_block"
                | "diamond_block"
                | "emerald_block"
                | "lapis_block"
                | "redstone_block"
                | "coal_block"
                | "copper_block"
                | "raw_iron_block"
                | "raw_gold_block"
                | "raw_copper_block"
        )
}

/// The pickaxe tier `name` needs: 1 wood, 2 stone, 3 iron, 4 diamond.
fn tier_needed(name: &str) -> u8 {
    let ore = name.strip_prefix("deepslate_").unwrap_or(name);
    match ore {
        "iron_ore" | "copper_ore" | "lapis_ore" | "iron_block" | "lapis_block" | "copper_block" | "raw_iron_block"
        | "raw_copper_block" => 2,
        "gold_ore" | "diamond_ore" | "emerald_ore" | "redstone_ore" | "gold_block" | "diamond_block"
        | "emerald_block" | "raw_gold_block" => 3,
        "obsidian" => 4,
        _ => 1,
    }
}

/// The tier of the pickaxe `tool` (0 for anything else, or an empty hand).
fn pickaxe_tier(tool: Option<ItemKind>) -> u8 {
    match tool.map(ItemKind::to_str) {
        Some("wooden_pickaxe" | "golden_pickaxe") => 1,
        Some("stone_pickaxe") => 2,
        Some("iron_pickaxe") => 3,
        Some("diamond_pickaxe" | "netherite_pickaxe") => 4,
        _ => 0,
    }
}

/// The item `client` holds in its main hand.
pub fn held(inventory: &Inventory, held: &HeldItem) -> Option<ItemKind> {
    inventory.slot(held.slot()).map(|s| s.item)
}

/// Puts `count` of `item` in the world at the centre of the broken block `pos`, on `layer`
/// (vanilla's spot, less its random offset: a drop does not move on the server).
pub fn spawn(commands: &mut Commands, layer: Entity, pos: BlockPos, (item, count): (ItemKind, u8)) {
    commands.spawn((
        ItemEntityBundle {
            item_stack: Stack(ItemStack::new(item, count, None)),
            layer: EntityLayerId(layer),
            position: Position::new([
                f64::from(pos.x) + 0.5,
                f64::from(pos.y) + 0.5 - ITEM.1 / 2.0,
                f64::from(pos.z) + 0.5,
            ]),
            ..Default::default()
        },
        Drop::default(),
    ));
}

/// Ages drops, removes the expired, and gives each drop a player touches (survival or
/// creative) as much of it as its inventory holds, as vanilla does: onto a stack of the same
/// item first, then into an empty slot, hotbar before the rest.
fn pick_up(
    mut commands: Commands,
    mut drops: Query<(Entity, &mut Drop, &mut Stack, &Position, &EntityId)>,
    mut players: Query<(Entity, &Position, &GameMode, &mut Inventory, &EntityId, &mut Client)>,
    mut layers: Query<&mut EntityLayer>,
) {
    for (entity, mut drop, mut stack, at, item_id) in &mut drops {
        drop.age += 1;
        if drop.age >= LIFETIME || stack.0.count() == 0 {
            commands.entity(entity).insert(Despawned);
            continue;
        }
        if drop.age < PICKUP_DELAY {
            continue;
        }
        for (player_entity, player, mode, mut inventory, player_id, mut client) in &mut players {
            if matches!(*mode, GameMode::Spectator) || !touches(player.0, at.0) {
                continue;
            }
            let taken = give(&mut inventory, stack.0.item, stack.0.count());
            if taken == 0 {
                continue;
            }
            let left = stack.0.count() - taken;
            stack.0.set_count(left);
            // The pickup animation: the collector is entity 0 to its own client (valence
            // reserves 0 for the client's own entity), its id to everyone else.
            let packet = |collector: i32| ItemPickupAnimationS2c {
                collected_entity_id: VarInt(item_id.get()),
                collector_entity_id: VarInt(collector),
                pickup_item_count: VarInt(i32::from(taken)),
            };
            client.write_packet(&packet(0));
            for mut layer in &mut layers {
                layer
                    .view_except_writer(ChunkPos::from_pos(at.0), player_entity)
                    .write_packet(&packet(player_id.get()));
            }
            if left == 0 {
                commands.entity(entity).insert(Despawned);
                break;
            }
        }
    }
}

/// Whether a player standing at `feet` reaches a drop at `item` (vanilla's boxes).
fn touches(feet: DVec3, item: DVec3) -> bool {
    let (dx, dz) = ((item.x - feet.x).abs(), (item.z - feet.z).abs());
    let reach_x = PLAYER.0 + REACH.0 + ITEM.0;
    let reach_z = PLAYER.0 + REACH.2 + ITEM.0;
    let (lo, hi) = (feet.y - REACH.1, feet.y + PLAYER.1 + REACH.1);
    dx < reach_x && dz < reach_z && item.y + ITEM.1 > lo && item.y < hi
}

/// Puts up to `count` of `item` in a player's `inventory`; returns how many fit.
pub fn give(inventory: &mut Inventory, item: ItemKind, count: u8) -> u8 {
    // The player window's slots: hotbar 36–44, then the main inventory 9–35.
    const ORDER: [std::ops::Range<u16>; 2] = [36..45, 9..36];
    let max = item.max_stack();
    let mut left = count;
    for merging in [true, false] {
        for range in ORDER {
            for slot in range {
                if left == 0 {
                    return count;
                }
                match inventory.slot(slot) {
                    Some(s) if merging && s.item == item && s.count() < max => {
                        let add = left.min(max - s.count());
                        let now = s.count() + add;
                        inventory.set_slot_amount(slot, now);
                        left -= add;
                    }
                    None if !merging => {
                        let add = left.min(max);
                        inventory.set_slot(slot, ItemStack::new(item, add, None));
                        left -= add;
                    }
                    _ => {}
                }
            }
        }
    }
    count - left
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: i32) -> BlockPos {
        BlockPos::new(x, 64, -3)
    }

    #[test]
    fn stone_needs_a_pickaxe_and_gives_cobblestone() {
        let pick = Some(ItemKind::WoodenPickaxe);
        assert_eq!(drop_of(BlockState::STONE, None, at(0)), None);
        assert_eq!(drop_of(BlockState::STONE, pick, at(0)), Some((ItemKind::Cobblestone, 1)));
        assert_eq!(drop_of(BlockState::DEEPSLATE, pick, at(0)), Some((ItemKind::CobbledDeepslate, 1)));
        assert_eq!(drop_of(BlockState::GRASS_BLOCK, None, at(0)), Some((ItemKind::Dirt, 1)));
        assert_eq!(drop_of(BlockState::SAND, None, at(0)), Some((ItemKind::Sand, 1)));
        assert_eq!(drop_of(BlockState::OAK_LOG, None, at(0)), Some((ItemKind::OakLog, 1)));
        assert_eq!(drop_of(BlockState::GLASS, None, at(0)), None);
        assert_eq!(drop_of(BlockState::WATER, None, at(0)), None);
    }

    #[test]
    fn ores_need_their_tier_and_give_vanilla_counts() {
        let (stone, iron) = (Some(ItemKind::StonePickaxe), Some(ItemKind::IronPickaxe));
        assert_eq!(drop_of(BlockState::IRON_ORE, Some(ItemKind::WoodenPickaxe), at(0)), None);
        assert_eq!(drop_of(BlockState::IRON_ORE, stone, at(0)), Some((ItemKind::RawIron, 1)));
        assert_eq!(drop_of(BlockState::DIAMOND_ORE, stone, at(0)), None);
        assert_eq!(drop_of(BlockState::DEEPSLATE_DIAMOND_ORE, iron, at(0)), Some((ItemKind::Diamond, 1)));
        assert_eq!(drop_of(BlockState::COAL_ORE, Some(ItemKind::WoodenPickaxe), at(0)), Some((ItemKind::Coal, 1)));
        let lapis: Vec<u8> =
            (0..200).filter_map(|x| drop_of(BlockState::LAPIS_ORE, stone, at(x))).map(|d| d.1).collect();
        assert_eq!(lapis.len(), 200);
        assert!(lapis.iter().all(|c| (4..=9).contains(c)), "{lapis:?}");
        assert!(lapis.contains(&4) && lapis.contains(&9), "the whole range is drawn");
        // The same block in the same place drops the same.
        assert_eq!(drop_of(BlockState::LAPIS_ORE, stone, at(7)), drop_of(BlockState::LAPIS_ORE, stone, at(7)));
    }

    #[test]
    fn jungle_and_berry_harvests_and_the_saplings_of_odd_leaves() {
        let beans = drop_of(BlockState::COCOA, None, at(1)).map(|d| d.0);
        assert_eq!(beans, Some(ItemKind::CocoaBeans));
        assert_eq!(drop_of(BlockState::SWEET_BERRY_BUSH, None, at(1)).map(|d| d.0), Some(ItemKind::SweetBerries));
        assert_eq!(drop_of(BlockState::VINE, None, at(1)), None);
        assert_eq!(drop_of(BlockState::MUSHROOM_STEM, None, at(1)), None);
        let caps: Vec<_> = (0..400).filter_map(|x| drop_of(BlockState::RED_MUSHROOM_BLOCK, None, at(x))).collect();
        assert!(caps.iter().all(|&(item, n)| item == ItemKind::RedMushroom && (1..=2).contains(&n)), "{caps:?}");
        assert!((20..120).contains(&caps.len()), "{} of 400 caps gave a mushroom", caps.len());
        let sapling = |leaves: BlockState| (0..400).find_map(|x| drop_of(leaves, None, at(x))).map(|d| d.0);
        assert_eq!(sapling(BlockState::MANGROVE_LEAVES), Some(ItemKind::MangrovePropagule));
        assert_eq!(sapling(BlockState::FLOWERING_AZALEA_LEAVES), Some(ItemKind::FloweringAzalea));
    }

    #[test]
    fn leaves_and_gravel_sometimes_give_a_sapling_or_flint() {
        let saplings = (0..2000).filter(|&x| drop_of(BlockState::OAK_LEAVES, None, at(x)).is_some()).count();
        assert!((50..150).contains(&saplings), "{saplings} saplings in 2000 leaves");
        assert_eq!(
            drop_of(BlockState::BIRCH_LEAVES, None, at(5)).map_or(ItemKind::BirchSapling, |d| d.0),
            ItemKind::BirchSapling
        );
        let flint =
            (0..2000).filter(|&x| drop_of(BlockState::GRAVEL, None, at(x)) == Some((ItemKind::Flint, 1))).count();
        assert!((120..280).contains(&flint), "{flint} flint in 2000 gravel");
    }

    #[test]
    fn a_drop_fills_stacks_of_its_item_first_then_empty_slots_hotbar_first() {
        let mut inv = Inventory::new(InventoryKind::Player);
        inv.set_slot(20, ItemStack::new(ItemKind::Dirt, 62, None));
        inv.set_slot(36, ItemStack::new(ItemKind::Stone, 1, None));
        assert_eq!(give(&mut inv, ItemKind::Dirt, 5), 5);
        assert_eq!(inv.slot(20).map(|s| s.count()), Some(64));
        assert_eq!(inv.slot(37).map(|s| (s.item, s.count())), Some((ItemKind::Dirt, 3)));
        // A full inventory takes nothing.
        for slot in 9..45 {
            inv.set_slot(slot, ItemStack::new(ItemKind::Stone, 64, None));
        }
        assert_eq!(give(&mut inv, ItemKind::Dirt, 1), 0);
    }

    #[test]
    fn a_player_reaches_drops_within_a_block_of_its_box() {
        let feet = DVec3::new(0.5, 64.0, 0.5);
        assert!(touches(feet, DVec3::new(1.5, 63.375, 0.5)), "the ground block beside it");
        assert!(touches(feet, DVec3::new(1.6, 65.0, 1.6)));
        assert!(!touches(feet, DVec3::new(2.5, 64.25, 0.5)), "two blocks away");
        assert!(!touches(feet, DVec3::new(0.5, 62.25, 0.5)), "two blocks below");
    }
}

//! The NBT both codec directions share: tag ids, a writer of big-endian NBT, and Anvil's
//! packing of palette indices into longs.

/// NBT tag ids.
pub mod tag {
    pub const END: u8 = 0;
    pub const BYTE: u8 = 1;
    pub const INT: u8 = 3;
    pub const LONG: u8 = 4;
    pub const BYTE_ARRAY: u8 = 7;
    pub const STRING: u8 = 8;
    pub const LIST: u8 = 9;
    pub const COMPOUND: u8 = 10;
    pub const LONG_ARRAY: u8 = 12;
}

/// Bits needed to write `n`.
pub fn bit_width(n: usize) -> u32 {
    usize::BITS - n.leading_zeros()
}

/// Longs of `count` values of `bits` bits packed as Anvil does (no value spans two longs).
pub fn packed_len(count: usize, bits: u32) -> usize {
    count.div_ceil((64 / bits) as usize)
}

/// Appends big-endian NBT to a byte vector. Every name and string written is ASCII (block,
/// property and biome identifiers), whose modified UTF-8 is the bytes themselves.
pub struct Writer(pub Vec<u8>);

impl Writer {
    pub fn tag(&mut self, id: u8, name: &str) {
        self.0.push(id);
        self.str_payload(name);
    }

    pub fn str_payload(&mut self, s: &str) {
        debug_assert!(s.bytes().all(|b| b != 0 && b.is_ascii()), "not plain ASCII: {s:?}");
        self.0.extend_from_slice(&(s.len() as u16).to_be_bytes());
        self.0.extend_from_slice(s.as_bytes());
    }

    pub fn byte(&mut self, name: &str, v: i8) {
        self.tag(tag::BYTE, name);
        self.0.push(v as u8);
    }

    pub fn int(&mut self, name: &str, v: i32) {
        self.tag(tag::INT, name);
        self.0.extend_from_slice(&v.to_be_bytes());
    }

    pub fn long(&mut self, name: &str, v: i64) {
        self.tag(tag::LONG, name);
        self.0.extend_from_slice(&v.to_be_bytes());
    }

    pub fn string(&mut self, name: &str, v: &str) {
        self.tag(tag::STRING, name);
        self.str_payload(v);
    }

    pub fn byte_array(&mut self, name: &str, v: &[u8]) {
        self.tag(tag::BYTE_ARRAY, name);
        self.0.extend_from_slice(&(v.len() as i32).to_be_bytes());
        self.0.extend_from_slice(v);
    }

    /// A list header; the caller writes `len` element payloads after it.
    pub fn list(&mut self, name: &str, element: u8, len: usize) {
        self.tag(tag::LIST, name);
        self.0.push(element);
        self.0.extend_from_slice(&(len as i32).to_be_bytes());
    }

    /// Closes a compound.
    pub fn end(&mut self) {
        self.0.push(tag::END);
    }

    /// A long array of `values` packed `bits` bits each, first value in the lowest bits.
    pub fn packed(&mut self, name: &str, values: &[u16], bits: u32) {
        let per_long = (64 / bits) as usize;
        self.tag(tag::LONG_ARRAY, name);
        self.0.extend_from_slice(&(packed_len(values.len(), bits) as i32).to_be_bytes());
        for group in values.chunks(per_long) {
            let mut long = 0u64;
            for (j, &v) in group.iter().enumerate() {
                long |= u64::from(v) << (j as u32 * bits);
            }
            self.0.extend_from_slice(&long.to_be_bytes());
        }
    }
}

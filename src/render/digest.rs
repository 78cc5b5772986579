//! FNV-1a (64-bit, the `fnv` crate): the one hash of raywave's files and keys. It names a
//! texture's texels, a scene's text in bench records and study identities, the variance
//! cache's keys, and the checksums of cache entries and shard parts. Not cryptographic: it
//! tells a changed or truncated file from an unchanged one, and keeps its meaning across
//! versions (the test vectors below).

use std::hash::Hasher;

/// FNV-1a's starting state (the offset basis): where every digest begins.
pub const START: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a of `bytes`, continued from the state `h` ([`START`] to begin), so that a digest can
/// be built part by part.
pub fn continued(h: u64, bytes: &[u8]) -> u64 {
    let mut hasher = fnv::FnvHasher::with_key(h);
    hasher.write(bytes);
    hasher.finish()
}

/// FNV-1a of `bytes`.
pub fn of(bytes: &[u8]) -> u64 {
    continued(START, bytes)
}

/// FNV-1a of `bytes` as 16 lower-case hex digits.
pub fn hex(bytes: &[u8]) -> String {
    format!("{:016x}", of(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FNV-1a's published 64-bit test vectors (the empty string, "a", "foobar"), so that the
    /// digests in saved records, parts and caches keep their meaning.
    #[test]
    fn the_digest_is_fnv1a_64() {
        assert_eq!(hex(b""), "cbf29ce484222325");
        assert_eq!(hex(b"a"), "af63dc4c8601ec8c");
        assert_eq!(hex(b"foobar"), "85944171f73967e8");
        assert_eq!(continued(of(b"foo"), b"bar"), of(b"foobar"));
    }
}

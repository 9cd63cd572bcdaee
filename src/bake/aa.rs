//! Antialiasing textures in `baked/aa/`: SMAA area/search (current and v2.8) and Jimenez MLAA area maps.

use super::Asset;

pub fn assets() -> Vec<Asset> {
    Vec::new()
}

//! Facial appearance maps (thesis ch. 7 and 8): the hemoglobin appearance rig of Jimenez et al., "A practical
//! appearance model for dynamic facial color" (ACM TOG 29(6), SIGGRAPH Asia 2010; thesis eq. 7.1–7.6), and the
//! partial-derivative wrinkle maps of Jimenez, Echevarria, Oat and Gutierrez, "Practical and Realistic Facial
//! Wrinkles Animation" (GPU Pro 2, 2011; thesis ch. 8, Table 8.1).
//!
//! Everything here is pure computation on typed buffers, except [`inputs`], which decodes user files from bytes
//! (the caller reads them). File encoding of the outputs lives in `crate::bake::facial`.
//!
//! | module | what |
//! | --- | --- |
//! | [`disk_stats`] | exact disk mean/σ (eq. 7.1) in O(r) per texel, brute-force reference |
//! | [`resample`] | area-weighted resampling for any ratio, bilinear reconstruction (texel centres, clamp) |
//! | [`hemoglobin_rig`] | rig parameters (eq. 7.4–7.5), evaluation (eq. 7.6), weights |
//! | [`appearance_transfer`] | a rig's relative changes carried onto another character's neutral map (§7.4.2) |
//! | [`synthetic`] | procedural capillary-like hemoglobin maps and expression targets, synthetic wrinkles |
//! | [`wrinkles`] | partial-derivative / difference normal encodings, cone clamp, zone masks, Table 8.1 |
//! | [`inputs`] | decoding of concentration maps, normal maps and masks with their value mappings |

pub mod appearance_transfer;
pub mod disk_stats;
pub mod hemoglobin_rig;
pub mod inputs;
pub mod resample;
pub mod synthetic;
pub mod wrinkles;

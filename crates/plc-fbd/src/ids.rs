//! The index of a block in its network, below both the FBD model ([`super::model`]) and the
//! function block types ([`super::types`]), which name blocks by it: kept apart so that neither
//! of the two imports the other back (the types use the model's blocks only through this index).

use plc_model::index_type;

index_type!(
    /// A block of one network: index into [`super::Network::blocks`] (blocks sorted by id).
    BlockId
);

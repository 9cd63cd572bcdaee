//! The passes of the thesis' skin shader that `run skin` adds around its SSS shader (issue 14, part B), chosen
//! per frame: the rig's eq. 7.6 in texture space ([`super::mesh_skin_inputs`], thesis §7.6).

use super::mesh_skin_inputs::RigPose;

/// What `run skin` adds to the SSS shader of [`super::skin_render::SkinRenderSettings`].
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SkinPasses {
    /// The rig's pose (eq. 7.6 weights and global state); None: the neutral pose (weight 1 on neutral, g = 1).
    pub rig_pose: Option<RigPose>,
}

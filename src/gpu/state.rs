//! What each image and buffer was last recorded for, so that a caller names only its next use and the recorder emits the
//! barrier from the last one (the per-resource state of kajiya's render graph and wgpu-core's trackers). Commands
//! run on one queue in the order they are submitted, and each recording is submitted in the order it is recorded,
//! so the last use recorded is the last use run before the next one.

use std::sync::{Arc, Mutex};

use super::access::Access;

/// The uses an image or a buffer was last recorded for, shared by everything that records its barriers (its
/// [`super::Image`] and a [`super::pipeline::RenderTarget`] drawn into it; its [`super::Buffer`]).
#[derive(Debug)]
pub(crate) struct UseState(Mutex<Vec<Access>>);

impl UseState {
    /// A resource with no use yet: its contents undefined, nothing to wait for.
    pub(crate) fn fresh() -> Arc<Self> {
        Arc::new(Self(Mutex::new(vec![Access::Nothing])))
    }

    /// The uses last recorded.
    pub(crate) fn get(&self) -> Vec<Access> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Records `next` as the image's uses and returns the ones it had.
    pub(crate) fn replace(&self, next: &[Access]) -> Vec<Access> {
        let mut uses = self.0.lock().unwrap_or_else(|e| e.into_inner());
        std::mem::replace(&mut *uses, next.to_vec())
    }

    /// Sets the image's uses without a barrier (a swapchain image handed back by the presentation engine).
    pub(crate) fn set(&self, uses: &[Access]) {
        self.replace(uses);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_use_is_the_next_barriers_before() {
        let state = UseState::fresh();
        assert_eq!(
            state.replace(&[Access::TransferWrite]),
            vec![Access::Nothing]
        );
        assert_eq!(
            state.replace(&[Access::GraphicsSampled, Access::ComputeSampled]),
            vec![Access::TransferWrite]
        );
        state.set(&[Access::ColorAttachment]);
        assert_eq!(
            state.replace(&[Access::Present]),
            vec![Access::ColorAttachment]
        );
    }
}

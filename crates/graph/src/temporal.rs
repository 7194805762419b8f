//! Temporal resources: state kept by key from one frame to the next.

use std::collections::HashMap;

use crate::barrier::Track;
use crate::resource::AnyDesc;

/// What the graph remembers of a temporal resource between frames.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct TemporalState {
    /// Its description; a new description starts a fresh resource.
    pub desc: AnyDesc,
    /// Its usage bits; new usage starts a fresh resource.
    pub usage: u32,
    /// Its synchronization state at the end of the last frame that used it.
    pub track: Track,
    /// Whether a pass that ran has written it since it was (re)created: its contents are
    /// defined.
    pub written: bool,
}

/// Temporal states by key.
#[derive(Clone, Debug, Default)]
pub(crate) struct TemporalStore {
    states: HashMap<String, TemporalState>,
}

impl TemporalStore {
    /// The state under `key` if it matches the description and usage asked for.
    pub fn get(&self, key: &str, desc: &AnyDesc, usage: u32) -> Option<&TemporalState> {
        self.states
            .get(key)
            .filter(|s| s.desc == *desc && s.usage == usage)
    }

    /// The state under `key`, whatever its description.
    pub fn latest(&self, key: &str) -> Option<&TemporalState> {
        self.states.get(key)
    }

    /// Whether the resource under `key`, described by `desc`, holds contents written by an
    /// earlier frame.
    pub fn written(&self, key: &str, desc: &AnyDesc) -> bool {
        self.states
            .get(key)
            .is_some_and(|s| s.desc == *desc && s.written)
    }

    /// Remember the end-of-frame states.
    pub fn commit(&mut self, states: &[(String, TemporalState)]) {
        for (key, state) in states {
            self.states.insert(key.clone(), state.clone());
        }
    }
}

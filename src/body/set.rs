//! [`DeformableBodySet`]: the soft bodies of a world, addressed by [`DeformableBodyHandle`]s, as rapier keeps
//! rigid bodies in a `RigidBodySet`.

use super::DeformableBody;

/// A stable reference to a body of a [`DeformableBodySet`]. A handle whose body was removed stays
/// invalid even if its slot is reused (the generation differs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct DeformableBodyHandle {
    index: u32,
    generation: u32,
}

impl DeformableBodyHandle {
    /// The slot index and generation, e.g. for logging or serialization.
    pub fn into_raw_parts(self) -> (u32, u32) {
        (self.index, self.generation)
    }

    /// The handle of slot `index` at `generation`, as given by
    /// [`DeformableBodyHandle::into_raw_parts`].
    pub fn from_raw_parts(index: u32, generation: u32) -> Self {
        Self { index, generation }
    }
}

#[derive(Debug, Clone)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
struct Slot {
    generation: u32,
    body: Option<DeformableBody>,
}

/// A collection of soft bodies with generational handles.
///
/// # Example
/// ```
/// use rapier_fvm::prelude::*;
///
/// let mut bodies = DeformableBodySet::new();
/// let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.4, 1000.0)?;
/// let ball = DeformableBodyBuilder::new(mesh::sphere(0.1, 4)?, material).build()?;
/// let handle = bodies.insert(ball);
/// assert_eq!(bodies.len(), 1);
/// let removed = bodies.remove(handle).expect("the body was there");
/// assert!(bodies.get(handle).is_none());
/// // The slot is reused, but the old handle stays invalid.
/// let again = bodies.insert(removed);
/// assert!(bodies.contains(again) && !bodies.contains(handle));
/// # Ok::<(), rapier_fvm::Error>(())
/// ```
#[derive(Debug, Clone, Default)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "SetParts")
)]
pub struct DeformableBodySet {
    slots: Vec<Slot>,
    free: Vec<u32>,
    len: usize,
}

/// A [`DeformableBodySet`] as written (feature `serde-serialize`): read back, its free slots
/// and count must agree with its bodies.
#[cfg(feature = "serde-serialize")]
#[derive(serde::Deserialize)]
struct SetParts {
    slots: Vec<Slot>,
    free: Vec<u32>,
    len: usize,
}

#[cfg(feature = "serde-serialize")]
impl TryFrom<SetParts> for DeformableBodySet {
    type Error = crate::Error;

    fn try_from(parts: SetParts) -> Result<Self, crate::Error> {
        let empty: Vec<u32> = (0..parts.slots.len() as u32)
            .filter(|&i| parts.slots[i as usize].body.is_none())
            .collect();
        let mut free = parts.free.clone();
        free.sort_unstable();
        if free != empty || parts.len != parts.slots.len() - empty.len() {
            return Err(crate::Error::InvalidSetting {
                parameter: "deformable body set",
                value: parts.len as f64,
                reason: "its free slots and body count do not match its bodies",
            });
        }
        Ok(Self {
            slots: parts.slots,
            free: parts.free,
            len: parts.len,
        })
    }
}

impl DeformableBodySet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a body and returns its handle.
    pub fn insert(&mut self, body: DeformableBody) -> DeformableBodyHandle {
        self.len += 1;
        if let Some(index) = self.free.pop() {
            let slot = &mut self.slots[index as usize];
            slot.body = Some(body);
            return DeformableBodyHandle {
                index,
                generation: slot.generation,
            };
        }
        self.slots.push(Slot {
            generation: 0,
            body: Some(body),
        });
        DeformableBodyHandle {
            index: (self.slots.len() - 1) as u32,
            generation: 0,
        }
    }

    /// Removes and returns the body of `handle`, or `None` if it is not in the set.
    pub fn remove(&mut self, handle: DeformableBodyHandle) -> Option<DeformableBody> {
        let slot = self.slots.get_mut(handle.index as usize)?;
        if slot.generation != handle.generation {
            return None;
        }
        let body = slot.body.take()?;
        slot.generation = slot.generation.wrapping_add(1);
        self.free.push(handle.index);
        self.len -= 1;
        Some(body)
    }

    /// The body of `handle`, if it is in the set.
    pub fn get(&self, handle: DeformableBodyHandle) -> Option<&DeformableBody> {
        let slot = self.slots.get(handle.index as usize)?;
        (slot.generation == handle.generation).then_some(slot.body.as_ref()?)
    }

    /// The body of `handle`, mutably, if it is in the set.
    pub fn get_mut(&mut self, handle: DeformableBodyHandle) -> Option<&mut DeformableBody> {
        let slot = self.slots.get_mut(handle.index as usize)?;
        if slot.generation != handle.generation {
            return None;
        }
        slot.body.as_mut()
    }

    /// The bodies of distinct `handles`, mutably, in the order given; handles not in the set
    /// are skipped.
    pub(crate) fn get_many_mut(
        &mut self,
        handles: &[DeformableBodyHandle],
    ) -> Vec<&mut DeformableBody> {
        let mut found: Vec<Option<&mut DeformableBody>> = handles.iter().map(|_| None).collect();
        for (handle, body) in self.iter_mut() {
            if let Some(i) = handles.iter().position(|h| *h == handle) {
                found[i] = Some(body);
            }
        }
        found.into_iter().flatten().collect()
    }

    /// Takes the bodies of distinct `handles` out of their slots for a while: until
    /// [`DeformableBodySet::give_back`] the slots stay reserved (the handles valid, the count
    /// unchanged) but lookups and iterators skip them, so that the lent bodies and the rest of
    /// the set can be worked on at once. Handles not in the set are skipped.
    pub(crate) fn lend(
        &mut self,
        handles: &[DeformableBodyHandle],
    ) -> Vec<(DeformableBodyHandle, DeformableBody)> {
        (handles.iter())
            .filter_map(|&handle| {
                let slot = self.slots.get_mut(handle.index as usize)?;
                let body = (slot.generation == handle.generation)
                    .then(|| slot.body.take())
                    .flatten()?;
                Some((handle, body))
            })
            .collect()
    }

    /// Puts bodies taken by [`DeformableBodySet::lend`] back into their slots.
    pub(crate) fn give_back(&mut self, lent: Vec<(DeformableBodyHandle, DeformableBody)>) {
        for (handle, body) in lent {
            let slot = &mut self.slots[handle.index as usize];
            debug_assert!(slot.generation == handle.generation && slot.body.is_none());
            slot.body = Some(body);
        }
    }

    /// Whether `handle` refers to a body of the set.
    pub fn contains(&self, handle: DeformableBodyHandle) -> bool {
        self.get(handle).is_some()
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the set has no body.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The bodies and their handles, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (DeformableBodyHandle, &DeformableBody)> {
        self.slots.iter().enumerate().filter_map(|(index, slot)| {
            let handle = DeformableBodyHandle {
                index: index as u32,
                generation: slot.generation,
            };
            slot.body.as_ref().map(|body| (handle, body))
        })
    }

    /// The bodies and their handles, mutably, in slot order.
    pub fn iter_mut(
        &mut self,
    ) -> impl Iterator<Item = (DeformableBodyHandle, &mut DeformableBody)> {
        self.slots
            .iter_mut()
            .enumerate()
            .filter_map(|(index, slot)| {
                let handle = DeformableBodyHandle {
                    index: index as u32,
                    generation: slot.generation,
                };
                slot.body.as_mut().map(|body| (handle, body))
            })
    }
}

impl std::ops::Index<DeformableBodyHandle> for DeformableBodySet {
    type Output = DeformableBody;

    /// # Panics
    /// If `handle` is not in the set, as rapier's sets do.
    fn index(&self, handle: DeformableBodyHandle) -> &DeformableBody {
        self.get(handle).expect("no soft body with this handle")
    }
}

impl std::ops::IndexMut<DeformableBodyHandle> for DeformableBodySet {
    fn index_mut(&mut self, handle: DeformableBodyHandle) -> &mut DeformableBody {
        self.get_mut(handle).expect("no soft body with this handle")
    }
}

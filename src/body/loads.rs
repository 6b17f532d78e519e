//! A body's loads besides gravity ([`crate::load`]): added, read and set by handle, and what
//! the integrators take from them: the dead loads with gravity's weight as one constant force
//! per node, the follower loads' forces and potential at the current positions.

use super::DeformableBody;
use crate::Error;
use crate::load::{ChamberTerms, Load, LoadHandle, LoadValue};
use rapier3d::glamx::DVec3;

impl DeformableBody {
    /// Adds a load (see [`crate::load`]); it acts from the next step on.
    ///
    /// # Errors
    /// [`Error::InvalidLoad`] for a load naming a node the body does not have, a degenerate
    /// triangle or path, or a non-finite value (see [`Load::check`]), and for a chamber whose
    /// walls enclose no volume at the body's positions (they face out of the cavity: a body's
    /// outer surface, or a cavity's triangles reversed).
    ///
    /// ```
    /// use rapier_fvm::prelude::*;
    ///
    /// // A 10 cm rubber cube, clamped at its base, pulled up by 10 kPa on its top face.
    /// let mesh = mesh::cuboid(DVec3::splat(0.05), [4, 4, 4])?;
    /// let top = mesh.surface_triangles_where(|p| p.y > 0.05 - 1e-9);
    /// let base = mesh.nodes_where(|p| p.y < -0.05 + 1e-9);
    /// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
    /// let mut cube = DeformableBodyBuilder::new(mesh, rubber).pinned_nodes(base).build()?;
    /// let pull = cube.add_load(Load::Traction { triangles: top, traction: DVec3::new(0.0, 1e4, 0.0) })?;
    /// // A controller changes it between frames.
    /// cube.set_load(pull, LoadValue::Vector(DVec3::new(0.0, 2e4, 0.0)))?;
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    pub fn add_load(&mut self, load: Load) -> Result<LoadHandle, Error> {
        load.check(self.node_count())?;
        if let Load::Chamber { triangles, .. } = &load
            && Load::enclosed_volume_of(triangles, &self.positions).is_some_and(|v| v <= 0.0)
        {
            return Err(Error::InvalidLoad {
                load: load.kind(),
                reason: "its walls enclose no cavity: they face out of it (a chamber's triangles \
                         are oriented out of the body, into the cavity)"
                    .into(),
            });
        }
        self.load_change_work += self.potential_of(&load);
        self.loads.push(load);
        self.load_edits += 1;
        Ok(LoadHandle(self.loads.len() as u32 - 1))
    }

    /// The body's loads, in the order they were added (a [`LoadHandle`] is the index).
    pub fn loads(&self) -> &[Load] {
        &self.loads
    }

    /// The load `handle`, if the body has it.
    pub fn load(&self, handle: LoadHandle) -> Option<&Load> {
        self.loads.get(handle.0 as usize)
    }

    /// Sets the magnitude of the load `handle` (a pressure in Pa, a tension in N, a chamber's
    /// volume in m³, a traction in Pa or a force density in N/m³), as a controller does between
    /// frames. A sleeping body wakes when one of its loads changes.
    ///
    /// # Errors
    /// [`Error::InvalidLoad`] for a handle the body does not have or a value [`Load::set`]
    /// refuses; the load is then unchanged.
    pub fn set_load(&mut self, handle: LoadHandle, value: LoadValue) -> Result<(), Error> {
        match self.loads.get_mut(handle.0 as usize) {
            Some(load) if load.value() == value => Ok(()),
            Some(load) => {
                let mut changed = load.clone();
                changed.set(value)?;
                let before = self.potential_of(&self.loads[handle.0 as usize]);
                self.load_change_work += self.potential_of(&changed) - before;
                self.loads[handle.0 as usize] = changed;
                self.load_edits += 1;
                Ok(())
            }
            None => Err(Error::InvalidLoad {
                load: "load",
                reason: format!("the body has no load {}", handle.0),
            }),
        }
    }

    /// The potential energy of the body's loads (J) at its current positions: `−Σ f·x` of the
    /// tractions and body forces, `p V` of each pressure (`V` the signed volume of the cone its
    /// triangles span from the world's origin, minus a cavity's volume), `T L` of each cable
    /// (`L` its length), the liquid's `K (V − V*)²/(2V*)` of each chamber. With the kinetic,
    /// elastic and gravitational energies it makes the energy the loads conserve while their
    /// values stay as they are.
    pub fn load_potential_energy(&self) -> f64 {
        self.loads.iter().map(|load| self.potential_of(load)).sum()
    }

    /// The work (J) changes of the loads' values did, summed since the body was built: each
    /// change (and each load added) adds the change of its potential energy at the positions
    /// then. An energy balance counts it as work done on the body from outside.
    pub(crate) fn load_change_work(&self) -> f64 {
        self.load_change_work
    }

    /// `load`'s potential energy (J) at the body's current positions.
    fn potential_of(&self, load: &Load) -> f64 {
        let volumes = self.control_volumes();
        load.potential(self.mesh.positions(), volumes, &self.positions)
    }

    /// Each node's rest control volume (m³), by node index: its mass over the density, or with
    /// [region materials](super::DeformableBodyBuilder::region_material) its lumped share of
    /// the elements' volumes.
    fn control_volumes(&self) -> impl Fn(usize) -> f64 + '_ {
        let density = self.material.density();
        let mixed = (self.element_materials.as_ref()).map(|m| m.control_volumes());
        move |n| match mixed {
            Some(volumes) => volumes[n],
            None => self.masses[n] / density,
        }
    }

    /// A bound (rad²/s²) on the squared highest angular frequency the follower loads' stiffness
    /// adds at the current positions: Gershgorin's, `max_n r_n / m_n` over the free nodes with
    /// `r_n` the row bound of [`Load::add_stiffness_bounds`] (a cable's `2T/d` against a light
    /// node of a fine mesh can exceed the elements' own stiffness). Zero without follower loads.
    pub(crate) fn load_frequency_squared(&self) -> f64 {
        if self.loads.is_empty() {
            return 0.0;
        }
        let mut rows = vec![0.0; self.node_count()];
        for load in &self.loads {
            load.add_stiffness_bounds(&self.positions, &mut rows);
        }
        (rows.iter().zip(&self.masses).zip(&self.pinned))
            .filter(|&((_, _), &pinned)| !pinned)
            .map(|((row, mass), _)| row / mass)
            .fold(0.0, f64::max)
    }

    /// Whether a load is a [chamber](Load::Chamber), whose liquid's tangent a Newton direction
    /// takes in by the Woodbury identity (so its system is solved by factorization).
    pub(crate) fn has_chambers(&self) -> bool {
        (self.loads.iter()).any(|load| matches!(load, Load::Chamber { .. }))
    }

    /// The rank-one tangents of the body's chambers at its current positions, zero on pinned
    /// nodes (see [`ChamberTerms`]).
    pub(crate) fn chamber_terms(&self) -> ChamberTerms {
        let mut terms = ChamberTerms::default();
        for (mut column, weight) in
            (self.loads.iter()).filter_map(|l| l.chamber_term(&self.positions))
        {
            for (g, &pinned) in column.iter_mut().zip(&self.pinned) {
                if pinned {
                    *g = DVec3::ZERO;
                }
            }
            terms.columns.push(column);
            terms.weights.push(weight);
        }
        terms
    }

    /// The node pairs the loads' tangents couple (`[a, b]`, `a > b`).
    pub(crate) fn load_pairs(&self) -> Vec<[u32; 2]> {
        self.loads.iter().flat_map(Load::coupled_pairs).collect()
    }

    /// The constant force on every free node over a step (N): its weight `m g` and the dead
    /// loads (traction, body force); zero on pinned nodes.
    pub(crate) fn dead_load(&self, gravity: DVec3) -> Vec<DVec3> {
        let mut load: Vec<DVec3> = self.masses.iter().map(|m| gravity * *m).collect();
        self.add_dead_forces(&mut load);
        for (f, &pinned) in load.iter_mut().zip(&self.pinned) {
            if pinned {
                *f = DVec3::ZERO;
            }
        }
        load
    }

    /// Adds the dead loads' forces (traction, body force; N per node) to `forces`.
    fn add_dead_forces(&self, forces: &mut [DVec3]) {
        let volumes = self.control_volumes();
        for load in &self.loads {
            load.add_dead_forces(self.mesh.positions(), &volumes, forces);
        }
    }

    /// Adds the follower loads' exact forces (pressure, cable, chamber; N per node) at the current
    /// positions to `forces`.
    pub(crate) fn add_follower_forces(&self, forces: &mut [DVec3]) {
        for load in &self.loads {
            load.add_follower_forces(&self.positions, forces);
        }
    }

    /// Per load, the point its potential's cone is measured from at the current positions (see
    /// [`Load::cone_origin`]), fixed over a solve.
    pub(crate) fn cone_origins(&self) -> Vec<DVec3> {
        (self.loads.iter())
            .map(|load| load.cone_origin(&self.positions))
            .collect()
    }

    /// Adds minus the gradient of the follower loads' potentials (N per node) at the current
    /// positions, cones measured from `origins`, to `forces`.
    pub(crate) fn add_potential_forces(&self, origins: &[DVec3], forces: &mut [DVec3]) {
        for (load, origin) in self.loads.iter().zip(origins) {
            load.add_potential_forces(*origin, &self.positions, forces);
        }
    }

    /// Adds the part of the follower forces no potential gives (N per node; a pressure's on the
    /// free rim of an open surface, see [`crate::load`]) at the current positions, cones
    /// measured from `origins`, to `forces`; zero on pinned nodes.
    pub(crate) fn add_rim_forces(&self, origins: &[DVec3], forces: &mut [DVec3]) {
        let mut rim = vec![DVec3::ZERO; self.node_count()];
        self.add_follower_forces(&mut rim);
        let mut conservative = vec![DVec3::ZERO; self.node_count()];
        self.add_potential_forces(origins, &mut conservative);
        for (n, force) in forces.iter_mut().enumerate() {
            if !self.pinned[n] {
                *force += rim[n] - conservative[n];
            }
        }
    }

    /// Adds every load's force but gravity's (N per node) at the current positions to
    /// `forces`: what an explicit substep adds to the internal forces.
    pub(crate) fn add_load_forces(&self, forces: &mut [DVec3]) {
        if !self.loads.is_empty() {
            self.add_dead_forces(forces);
            self.add_follower_forces(forces);
        }
    }

    /// The follower loads' potential (J) at the current positions, measured from `start` (m),
    /// cones from `origins`.
    pub(crate) fn follower_potential(&self, origins: &[DVec3], start: &[DVec3]) -> f64 {
        (self.loads.iter().zip(origins))
            .map(|(load, origin)| load.follower_potential(*origin, start, &self.positions))
            .sum()
    }
}

//! Contact queries: where a collider is at an instant of the step, and the
//! gap and contact manifolds of a pair there.

use super::super::backend::math::{Pose, Real};
use super::super::backend::parry::query::{
    ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use super::super::backend::parry::shape::{Shape, ShapeType};
use super::super::backend::prelude::ColliderHandle;
use super::super::support::Geometry;
use super::{body_pose, Candidate, ImpactPass, World};

impl ImpactPass {
    /// Pose of collider `c` at time `t` of the step.
    pub(super) fn collider_pose(
        &mut self,
        world: &World,
        c: ColliderHandle,
        t: f64,
    ) -> Option<Pose> {
        let co = world.colliders.get(c)?;
        match co
            .parent()
            .and_then(|h| world.bodies.get(h).map(|rb| (h, rb)))
        {
            Some((h, rb)) if rb.is_dynamic() => {
                let dt = self.motion.dt;
                let (com, angle) = self.build_path(h, rb).at(t, dt);
                let offset = co.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                Some(body_pose(rb, com, angle) * offset)
            }
            _ => Some(*co.position()),
        }
    }

    /// Signed gap (m) of a candidate's pair at time `t`; `None` if beyond
    /// `reach` (m).
    pub(super) fn gap(&mut self, world: &World, k: usize, t: f64, reach: f64) -> Option<f64> {
        let Candidate {
            colliders: [a, b],
            geometry,
            ..
        } = self.candidates[k];
        let pa = self.collider_pose(world, a, t)?;
        let pb = self.collider_pose(world, b, t)?;
        let (sa, sb) = (
            world.colliders.get(a)?.shape(),
            world.colliders.get(b)?.shape(),
        );
        self.pairs_queried += 1;
        // A composite shape is queried sub-shape by sub-shape within the
        // reach: only gaps near zero matter to the search.
        let reach = match geometry {
            Geometry::Convex => reach,
            Geometry::Composite => reach.min(4.0 * world.prediction.max(world.allowed)),
        };
        let count = self.manifolds_of(geometry, &pa, sa, &pb, sb, reach as Real);
        self.manifolds[..count]
            .iter()
            .flat_map(|m| m.points.iter().map(|p| f64::from(p.dist)))
            .min_by(f64::total_cmp)
    }

    /// Fills `manifolds` with the contact manifolds of two shapes at poses
    /// `pa` and `pb`, points within `reach`; returns how many there are.
    /// The manifold query (clipping for polygons) keeps its buffers; the
    /// plain contact query runs EPA when the pair penetrates, which
    /// allocates. Composite shapes allocate their sub-shape workspace.
    pub(super) fn manifolds_of(
        &mut self,
        geometry: Geometry,
        pa: &Pose,
        sa: &dyn Shape,
        pb: &Pose,
        sb: &dyn Shape,
        reach: Real,
    ) -> usize {
        match geometry {
            Geometry::Convex => self.convex_manifold(pa, sa, pb, sb, reach),
            Geometry::Composite => self.composite_manifolds_of(pa, sa, pb, sb, reach),
        }
    }

    /// [`Self::manifolds_of`] for two convex shapes: one manifold.
    fn convex_manifold(
        &mut self,
        pa: &Pose,
        sa: &dyn Shape,
        pb: &Pose,
        sb: &dyn Shape,
        reach: Real,
    ) -> usize {
        // parry's GJK misses a segment touching a box flat at gaps
        // near 10⁻⁹ when the segment is the first shape (normal along
        // the segment, no points): the segment goes second, and the
        // manifold is flipped back.
        let swap = segment_like(sa) && !segment_like(sb);
        let (pos12, s1, s2) = if swap {
            (pb.inv_mul(pa), sb, sa)
        } else {
            (pa.inv_mul(pb), sa, sb)
        };
        if self.manifolds.is_empty() {
            self.manifolds.push(ContactManifold::new());
        }
        let m = &mut self.manifolds[0];
        // a fresh manifold: parry starts its GJK from the normal a reused one
        // kept (`local_n1`), which made the result depend on the pair and
        // instant queried before
        *m = ContactManifold::new();
        let ok = DefaultQueryDispatcher
            .contact_manifold_convex_convex(&pos12, s1, s2, None, None, reach, m);
        if swap {
            flip_manifold(m);
        }
        usize::from(ok.is_ok())
    }

    /// [`Self::manifolds_of`] for a composite shape: one manifold per pair
    /// of sub-shapes.
    fn composite_manifolds_of(
        &mut self,
        pa: &Pose,
        sa: &dyn Shape,
        pb: &Pose,
        sb: &dyn Shape,
        reach: Real,
    ) -> usize {
        let count = composite_manifolds(&pa.inv_mul(pb), sa, sb, reach, &mut self.manifolds);
        // The same GJK miss for a sub-shape, in either order: when
        // some sub-shapes touch and others have no points, the pair
        // is queried again the other way round and each empty
        // manifold takes the other query's points.
        let partial = |ms: &[ContactManifold<(), ()>]| {
            ms.iter().any(|m| m.points.is_empty()) && ms.iter().any(|m| !m.points.is_empty())
        };
        if partial(&self.manifolds[..count]) {
            let other = composite_manifolds(&pb.inv_mul(pa), sb, sa, reach, &mut self.spare);
            for m in &mut self.spare[..other] {
                flip_manifold(m);
                if m.points.is_empty() {
                    continue;
                }
                let same = self.manifolds[..count]
                    .iter_mut()
                    .find(|k| k.subshape1 == m.subshape1 && k.subshape2 == m.subshape2);
                if let Some(k) = same.filter(|k| k.points.is_empty()) {
                    std::mem::swap(k, m);
                }
            }
        }
        count
    }
}

/// The manifolds of a pair with a composite shape (one per pair of
/// sub-shapes) into `out`; how many.
fn composite_manifolds(
    pos12: &Pose,
    sa: &dyn Shape,
    sb: &dyn Shape,
    reach: Real,
    out: &mut Vec<ContactManifold<(), ()>>,
) -> usize {
    out.clear();
    let mut workspace = None;
    let ok = DefaultQueryDispatcher.contact_manifolds(pos12, sa, sb, reach, out, &mut workspace);
    if ok.is_ok() {
        out.len()
    } else {
        0
    }
}

/// A segment or a polyline (made of segments).
fn segment_like(s: &dyn Shape) -> bool {
    matches!(s.shape_type(), ShapeType::Segment | ShapeType::Polyline)
}

/// A contact manifold of shapes 1 and 2 as the manifold of 2 and 1.
fn flip_manifold(m: &mut ContactManifold<(), ()>) {
    std::mem::swap(&mut m.local_n1, &mut m.local_n2);
    std::mem::swap(&mut m.subshape1, &mut m.subshape2);
    let (pos1, pos2) = (m.subshape_pos1().copied(), m.subshape_pos2().copied());
    m.set_subshape_pos1(pos2);
    m.set_subshape_pos2(pos1);
    for p in m.points.iter_mut() {
        std::mem::swap(&mut p.local_p1, &mut p.local_p2);
        std::mem::swap(&mut p.fid1, &mut p.fid2);
    }
}

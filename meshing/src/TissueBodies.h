#pragma once
/// @file TissueBodies.h
/// The soft-tissue volume bodies (sim::VolumeBodies): the pectorals and, with the shoulder girdle, the bulk
/// of the shoulders, "simulated as volume-preserving bodies and attached with a number of strategically
/// placed, zero-length springs" (Zordan et al. 2004, Section 7).
///
/// Each body is a lens: a grid of deep nodes on the bones, and a
/// grid of free superficial nodes over its interior, lifted off the deep face along the outward normal by the
/// thickness profile T sin(pi u)^0.6 sin(pi v)^0.6 (u, v in [0, 1] across the grid). The two faces share the
/// deep rim, so the surface is closed. Springs run along every surface edge and through the thickness (each
/// superficial node to the deep node below it and to that node's four neighbours, the paper's "internal
/// spring supports"). The gains and thicknesses are muscle_gains.json `tissue_bodies` (TissueGains); without
/// that block no body is built. Each deep node is tied to one bone: where the muscle takes origin by three
/// two-sided springs along the world axes, 20 mm long (for small motions the paper's zero-length spring,
/// stiffness k I); where it slides on the bone by one spring along the chest wall's normal (the deep face's,
/// from the grid: a rib's own in-plane normal tilts about 40 deg down at the front of ribs 4-6, and ties
/// along it let 20-26 deep nodes sink 2-3 mm into the ribs at the end of a deep inhale), anchored kSlideArm
/// (100 mm) inside it and as stiff along that line: it holds the node's distance to the chest wall and hardly
/// a slide across it, as loose areolar tissue lets the pectoral slide on the chest wall. Tied rigidly all
/// over, the pectorals would bind ribs 2-6 and the sternum into one plate and stiffen the chest wall.
/// The skin lies over the bodies (they are obstacles of its registration, Skin.cpp) but is not bound to them.
///   - pectoral_right, pectoral_left: over ribs 2-6 anteriorly (a row of 5 deep nodes on each rib: 25 deep
///     and 9 superficial nodes; with rows midway between the ribs and 7 columns the lenses made the step 1.7
///     times dearer, and the skin is not bound to them), from the sternal border (deep nodes tied to
///     the sternum) to a third of the way from the costochondral junction to the rib's most lateral point;
///     tied firmly at the sternal border and along rib 2 (the upper edge, standing in for the clavicular
///     origin: it carries the lens's weight), sliding elsewhere.
///   - deltoid_right, deltoid_left (anatomy option `shoulder_girdle`): a cap over the glenohumeral joint,
///     round the front, the side and the back of the humeral head and the upper humerus, its upper rows tied
///     to the scapula (acromion), the rest to the humerus.

#include "Skeleton.h"
#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// Appends the tissue bodies of `a` to `model`: Tissue nodes (after the gut's), their volume bodies and their
/// Cartilage springs. `model.bodies` must hold the centres of mass. Does nothing when `a` has no
/// `tissue_bodies` gains. @throws sim::Error when a body would enclose no volume.
void buildTissueBodies(const AnatomyParams& a, const Skeleton& sk, sim::Model& model);

}  // namespace pneuma::meshing

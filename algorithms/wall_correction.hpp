// The walls' correction module: the velocity-position correction against the domain walls, the
// static boxes and the static mesh objects (wall_contact.hpp; the paper's Algorithm 1, step 7,
// with the boundary's mass infinite). It has no stage of its own: the fluid applies it to every
// predicted position in PCISPH and after the integration (fluid.hpp), and the moving solids'
// correction keeps to it (solid_contact.hpp). Its arrays are the boxes' faces and the objects'
// signed distance grids.
#pragma once
#include <algorithm>
#include <vector>

#include "algorithms/module.hpp"
#include "algorithms/wall_contact.hpp"

MW_BACKEND_BEGIN

class WallCorrection final : public Module {
   public:
    WallCorrection(const SimulationParams& params, bool has_fluid) {
        if (!params.boundary.correction) return;
        const Real r0 = params.fluid.spacing;
        if (params.boundary.walls) {
            if (!(params.boundary.wall_gap >= 0))
                throw InputError("simulation setup: the domain walls' correction needs the walls' gap (params.boundary.wall_gap)");
            walls_ = WallContact::for_domain(params.domain_min, params.domain_max, params.boundary.wall_gap, r0,
                                             params.dimensions);
        }
        // Boxes and objects keep fluid out; without fluid there is nothing to keep.
        if (!has_fluid) return;
        if (!params.boundary.static_boxes.empty()) {
            std::vector<ContactBox> boxes;
            for (const StaticBoxFaces& b : params.boundary.static_boxes)
                boxes.push_back(contact_box(b, r0, params.dimensions));
            boxes_.upload(boxes);
            walls_.boxes = boxes_.cview();
        }
        if (!params.boundary.static_objects.empty()) {
            std::size_t values = 0;
            for (const ContactField& c : params.boundary.static_objects) {
                if (c.field.nx < 2 || c.field.ny < 2 || c.field.nz < 2 || !(c.field.inv_spacing > 0))
                    throw InputError("simulation setup: a static object's distance grid needs 2 nodes or more per "
                                     "axis and a positive spacing");
                values = std::max(values, std::size_t(c.field.first) + std::size_t(c.field.nx) *
                                                                           std::size_t(c.field.ny) *
                                                                           std::size_t(c.field.nz));
            }
            if (values > params.boundary.static_object_distances.size())
                throw InputError("simulation setup: a static object's distance grid reaches past the values given");
            // Fluid rests closer to an object's surface particles than to a wall's layer: the band
            // is kStaticObjectContact r0 from its surface.
            std::vector<ContactField> objects = params.boundary.static_objects;
            for (ContactField& c : objects) c.contact = Real(kStaticObjectContact * double(r0));
            objects_.upload(objects);
            object_distances_.upload(params.boundary.static_object_distances);
            walls_.objects = objects_.cview();
            walls_.object_distances = object_distances_.cview();
        }
    }

    // What the kernels apply (planes at the largest finite values where there are no walls).
    const WallContact& walls() const { return walls_; }
    std::size_t bytes() const override { return boxes_.bytes() + objects_.bytes() + object_distances_.bytes(); }

   private:
    WallContact walls_;
    DeviceArray<ContactBox> boxes_;        // the static boxes' faces
    DeviceArray<ContactField> objects_;    // the static mesh objects' distance grids
    DeviceArray<Real> object_distances_;   // ... and their values, one object after another
};

MW_BACKEND_END

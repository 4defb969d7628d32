// What a run of many short chunks (`run N pre no post no`, pyhost.engines.liggghts.Liggghts.run)
// should not pay for on every chunk.
//
// A mesh wall's neighbour list (FixNeighlistMesh) precomputes, for a mesh and a domain that
// do not change, the bins each triangle may reach (generate_bin_list, a search over every
// triangle's bounding box). Its post_run throws that away "for a possible next run", so that
// every run rebuilds it at its first neighbour build: on Debian's chute_wear tutorial, 1,000
// runs of 100 steps took 19.4 s against 12.5 s for one run of 100,000 steps, 31 % of the
// time in generate_bin_list (perf). Before a run without set-up (`pre no`: no bins are set up
// again, the box and the neighbour settings are those of the last run), the bins of the last
// run still hold, and the list is told so: as if built at the last bin set-up. A mesh whose
// triangle count changed, or a moving mesh or changing box (the precomputed bins are not
// used then), is left alone.
#include "lammps.h"
#include "modify.h"
#include "neighbor.h"
#include "tri_mesh.h"
#define protected public
#include "fix_neighlist_mesh.h"
#undef protected
#include <cstring>

using namespace LAMMPS_NS;

extern "C" {

// Returns the number of mesh neighbour lists told to keep their bins.
int collheat_keep_mesh_bins(void *ptr)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    int kept = 0;
    for (int f = 0; f < lmp->modify->nfix; ++f) {
        if (std::strcmp(lmp->modify->fix[f]->style, "neighlist/mesh") != 0) continue;
        FixNeighlistMesh *list = static_cast<FixNeighlistMesh *>(lmp->modify->fix[f]);
        const size_t nall = size_t(list->mesh_->sizeLocal() + list->mesh_->sizeGhost());
        if (list->last_bin_update >= 0 || list->changingMesh || list->changingDomain || list->triangles.size() != nall)
            continue;
        list->last_bin_update = lmp->neighbor->last_setup_bins_timestep;
        ++kept;
    }
    return kept;
}

}

// State of LIGGGHTS fixes that Debian's LIGGGHTS 3.8 does not carry through write_restart /
// read_restart, read and set by the host around a checkpoint (pyhost/checkpoint.py).
//
// fix move/mesh: its time since the motion began (FixMoveMesh::time_), from which wiggle,
// rotation and the other movers take their phase. A restart re-defines the fix with the time at
// zero: measured on cases/silo-heat, the shaken plate moved 0.04 mm off its path within 95 steps
// of the restart and the bed had 30 % more collisions. The member is private; it is reached
// here only, by reading the class as public (the layout is unchanged).
//
// the random generators of insertion: a region's (fix insert/rate/region and insert/pack draw
// the positions of new particles from it), the insertion fix's, and those of the particle
// distributions and templates it draws sizes and types from. The fixes write some of these
// into the restart file, but on reading it they reset the region's generator from the
// insertion's own state, not to where the region's stream was, and not every template
// generator is kept: on cases/silo-heat the first insertion after a restart put its particles
// elsewhere than the run never stopped. The members are protected.
//
// the progress of each insertion fix (fix insert/pack, insert/stream, insert/rate/region): the
// step of its next insertion (Fix::next_reneighbor; 0 once it has inserted all it will) and what
// it inserted so far. FixInsert::restart (fix_insert.cpp) takes the count and the mass back, but
// keeps the next step only when it is not 0: an insertion that was done ('insert_every once',
// or a count reached) is scheduled again at the step after the restart: measured, a pour of 50
// beads by 'insert/pack ... insert_every once' had 68 after a restart, and an insert/rate/region
// done before it stopped the restarted run at its next checkpoint ('start' step can not be
// before current step, from the fix's init in write_restart).
#include <cstring>
#include "lammps.h"
#include "modify.h"
#include "domain.h"
#include "fix.h"
#include "random_park.h"
#define private public
#define protected public
#include "fix_move_mesh.h"
#include "region.h"
#include "fix_insert.h"
#include "fix_particledistribution_discrete.h"
#include "fix_template_sphere.h"
#undef protected
#undef private

using namespace LAMMPS_NS;

extern "C" {

// The time [s] of `fix <id> ... move/mesh`: read into *time (set == 0) or set from it (set != 0).
// Returns 0, or -1 when there is no such fix.
int collheat_move_mesh_time(void *ptr, const char *id, double *time, int set)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    const int i = lmp->modify->find_fix(id);
    if (i < 0 || std::strncmp(lmp->modify->fix[i]->style, "move/mesh", 9) != 0) return -1;
    FixMoveMesh *fix = static_cast<FixMoveMesh *>(lmp->modify->fix[i]);
    if (set) fix->time_ = *time;
    else *time = fix->time_;
    return 0;
}

static Fix *fix_of_style(LAMMPS *lmp, const char *id, const char *style)
{
    const int i = lmp->modify->find_fix(id);
    if (i < 0 || std::strncmp(lmp->modify->fix[i]->style, style, std::strlen(style)) != 0) return NULL;
    return lmp->modify->fix[i];
}

// The state of one random generator on this rank: of region <id> (what = "region"), of fix <id>
// insert/* ("insert"), particledistribution/discrete ("distribution"), or particletemplate/sphere
// ("template_insertion", "template_mc"). Read into *state (set == 0) or set from it (set != 0).
// Returns 0, or -1 when there is no such generator.
int collheat_random_state(void *ptr, const char *what, const char *id, int *state, int set)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    RanPark *random = NULL;
    if (std::strcmp(what, "region") == 0) {
        const int i = lmp->domain->find_region(id);
        if (i >= 0) random = lmp->domain->regions[i]->random;
    } else if (std::strcmp(what, "insert") == 0) {
        if (Fix *fix = fix_of_style(lmp, id, "insert/")) random = static_cast<FixInsert *>(fix)->random;
    } else if (std::strcmp(what, "distribution") == 0) {
        if (Fix *fix = fix_of_style(lmp, id, "particledistribution/discrete"))
            random = static_cast<FixParticledistributionDiscrete *>(fix)->random;
    } else if (std::strncmp(what, "template_", 9) == 0) {
        if (Fix *fix = fix_of_style(lmp, id, "particletemplate/sphere")) {
            FixTemplateSphere *t = static_cast<FixTemplateSphere *>(fix);
            random = std::strcmp(what, "template_mc") == 0 ? t->random_mc : t->random_insertion;
        }
    }
    if (random == NULL) return -1;
    if (set) random->reset(*state);
    else *state = random->state();
    return 0;
}

// The progress of `fix <id> insert/*` (the same on every rank): state[0] the step of its next
// insertion (0: none), [1] the particles inserted so far, [2] their mass [kg], [3] the step of its
// first insertion, [4] that of its most recent (-1: none yet). Read into state (set == 0) or set
// from it (set != 0). Returns 0, or -1 when there is no such fix.
int collheat_insert_progress(void *ptr, const char *id, double *state, int set)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    Fix *fix = fix_of_style(lmp, id, "insert/");
    if (fix == NULL) return -1;
    FixInsert *ins = static_cast<FixInsert *>(fix);
    if (set) {
        ins->next_reneighbor = static_cast<bigint>(state[0]);
        ins->ninserted = static_cast<int>(state[1]);
        ins->massinserted = state[2];
        ins->first_ins_step = static_cast<int>(state[3]);
        ins->most_recent_ins_step = static_cast<int>(state[4]);
    } else {
        state[0] = static_cast<double>(ins->next_reneighbor);
        state[1] = ins->ninserted;
        state[2] = ins->massinserted;
        state[3] = ins->first_ins_step;
        state[4] = ins->most_recent_ins_step;
    }
    return 0;
}

}

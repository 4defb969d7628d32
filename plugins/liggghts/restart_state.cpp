// State of LIGGGHTS fixes that Debian's LIGGGHTS 3.8 does not carry through write_restart /
// read_restart, read and set by the host around a checkpoint (pyhost/checkpoint.py).
//
// fix move/mesh: its time since the motion began (FixMoveMesh::time_), from which wiggle,
// rotation and the other movers take their phase. A restart re-defines the fix with the time at
// zero: measured on cases/silo-heat, the shaken plate moved 0.04 mm off its path within 95 steps
// of the restart and the bed had 30 % more collisions. The member is private; it is reached
// here only, by reading the class as public (the layout is unchanged).
#include <cstring>
#include "lammps.h"
#include "modify.h"
#include "fix.h"
#define private public
#include "fix_move_mesh.h"
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

}

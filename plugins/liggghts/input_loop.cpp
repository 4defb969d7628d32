// What LIGGGHTS' own input loop keeps that the host's (pyhost.script.Program) needs to follow
// a script as LIGGGHTS would: `next` on an index or loop variable with no value left removes
// the variable and sets Input::jump_skip, so that the next `jump` is skipped (input.cpp,
// next_command and jump). The host runs `next` through LIGGGHTS and its jumps itself, so it
// reads the flag and clears it, as LIGGGHTS' jump would.
#include "lammps.h"
#define protected public
#include "input.h"
#undef protected

using namespace LAMMPS_NS;

extern "C" {

// Returns 1 if a `next` since the last call exhausted its variable (LIGGGHTS' jump_skip), and
// clears the flag.
int collheat_take_jump_skip(void *ptr)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    int skip = lmp->input->jump_skip;
    lmp->input->jump_skip = 0;
    return skip;
}

}

// What LIGGGHTS 3.8's C library interface lacks, for pyhost/liggghts.py:
// the size of a local compute (its row count is not in the C API), the force array of a
// `fix external pf/array`, and a report of LIGGGHTS' last error when it ends the process
// (through exit or MPI_Abort).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mpi.h>
#include "lammps.h"
#include "modify.h"
#include "compute.h"
#include "fix_external.h"
#include "update.h"

using namespace LAMMPS_NS;

static char exit_log[4096] = "";
static LAMMPS *watched = nullptr;

// On exit(1) from Error::all, or MPI_Abort from Error::one, print LIGGGHTS' last ERROR line
// to stderr: the screen output goes to a log file, so without this the process would end
// without a word. pyhost.liggghts disarms it on a normal exit of Python.
static void report_exit()
{
    if (!exit_log[0]) return;
    FILE *f = std::fopen(exit_log, "r");
    if (!f) return;
    char line[4096], last[4096] = "";
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "ERROR", 5) == 0) std::strcpy(last, line);
    std::fclose(f);
    if (last[0])
        std::fprintf(stderr, "LIGGGHTS ended the process: %s(log: %s)\n", last, exit_log);
}

extern "C" {

// Error::one ends with MPI_Abort, which skips atexit: this definition, found before
// OpenMPI's because pyhost.liggghts loads this library first, reports and then aborts.
int MPI_Abort(MPI_Comm comm, int code)
{
    if (watched && watched->screen) std::fflush(watched->screen);  // Error::one does not
    report_exit();
    return PMPI_Abort(comm, code);
}

void collheat_watch_exit(void *ptr, const char *logfile)
{
    static bool registered = false;
    watched = static_cast<LAMMPS *>(ptr);
    std::snprintf(exit_log, sizeof exit_log, "%s", logfile ? logfile : "");
    if (!registered) { std::atexit(report_exit); registered = true; }
}

// Flush LIGGGHTS' screen output, so that a forked copy does not write it a second time.
void collheat_flush(void *ptr)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    if (lmp->screen) std::fflush(lmp->screen);
    if (lmp->logfile) std::fflush(lmp->logfile);
}

// Send LIGGGHTS' screen output to another file from now on (for a forked copy: the
// parent's stream is left alone, its buffer was flushed before the fork).
int collheat_set_screen(void *ptr, const char *path)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    FILE *f = std::fopen(path, "w");
    if (!f) return -1;
    lmp->screen = f;
    return 0;
}

// Rows and columns of a local compute, evaluated on the current step; its data pointer.
// Returns 0, or -1 when there is no compute of that name or it produces no local data.
int collheat_compute_local(void *ptr, const char *id, int *rows, int *cols, double **data)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    int i = lmp->modify->find_compute(id);
    if (i < 0) return -1;
    Compute *c = lmp->modify->compute[i];
    if (!c->local_flag) return -1;
    if (c->invoked_local != lmp->update->ntimestep) {
        c->invoked_local = lmp->update->ntimestep;
        c->compute_local();
    }
    *rows = c->size_local_rows;
    *cols = c->size_local_cols;
    if (data) *data = c->size_local_cols ? (c->size_local_rows ? c->array_local[0] : nullptr)
                                         : c->vector_local;
    return 0;
}

// The per-atom force array (nlocal x 3, contiguous) of a `fix external pf/array`, or null.
double *collheat_fix_external_force(void *ptr, const char *id)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    int i = lmp->modify->find_fix(id);
    if (i < 0 || std::strcmp(lmp->modify->fix[i]->style, "external") != 0) return nullptr;
    FixExternal *f = static_cast<FixExternal *>(lmp->modify->fix[i]);
    return f->fexternal ? f->fexternal[0] : nullptr;
}

}

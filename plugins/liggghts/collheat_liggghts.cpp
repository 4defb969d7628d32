// What LIGGGHTS 3.8's C library interface lacks, for pyhost/liggghts.py:
// the size of a local compute (its row count is not in the C API), the force array of a
// `fix external pf/array`, commands and runs that return LIGGGHTS' error instead of ending
// the process, and a report of LIGGGHTS' last error when it does end the process (through
// exit or MPI_Abort).
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <mpi.h>
#include "lammps.h"
#include "library.h"
#include "error.h"
#include "modify.h"
#include "compute.h"
#include "fix.h"
#include "fix_external.h"
#include "update.h"
#include "output.h"
#include "atom.h"

using namespace LAMMPS_NS;

static char exit_log[4096] = "";
static char context[1024] = "";      // what the host was running (the script's file and line)
static bool reported = false;
static LAMMPS *watched = nullptr;

// On exit(1) from Error::all, or MPI_Abort from Error::one, print LIGGGHTS' last ERROR line
// to stderr: the screen output goes to a log file, so without this the process would end
// without a word. pyhost.liggghts disarms it on a normal exit of Python.
static void report_exit()
{
    if (!exit_log[0] || reported) return;
    FILE *f = std::fopen(exit_log, "r");
    if (!f) return;
    char line[4096], last[4096] = "";
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "ERROR", 5) == 0) std::strcpy(last, line);
    std::fclose(f);
    if (last[0])
        std::fprintf(stderr, "LIGGGHTS ended the process%s%s: %s(log: %s)\n", context[0] ? " at " : "", context,
                     last, exit_log);
}

// ---- errors that return --------------------------------------------------------------
// LIGGGHTS 3.8 ends the process on any error: Error::all and its kin call exit(1) (every
// rank together), Error::one calls MPI_Abort (one rank). This library is loaded before
// libliggghts with RTLD_GLOBAL, and libliggghts calls them through its PLT, so the
// definitions below take their place. Inside collheat_command / collheat_file (``armed``)
// they write LIGGGHTS' own ERROR line and jump back there, which returns 1 with the message
// (collheat_failure). Outside, they do what LIGGGHTS does (the original, found by dlsym).
// After such a return the LIGGGHTS instance is left mid-command: read its atoms if need be,
// but run nothing more (pyhost/engines/liggghts.py refuses to).
static std::jmp_buf *armed = nullptr;
static char failure[4096] = "";

template <typename Fn>
static Fn original(const char *symbol) { return reinterpret_cast<Fn>(dlsym(RTLD_NEXT, symbol)); }

// Every rank of the world calls this together (as Error::all): rank 0 writes the line.
static void fail_all(MPI_Comm world, FILE *screen, FILE *logfile, const char *text)
{
    MPI_Barrier(world);
    int me;
    MPI_Comm_rank(world, &me);
    std::snprintf(failure, sizeof failure, "ERROR: %s", text);
    if (me == 0) {
        if (screen) { std::fprintf(screen, "%s\n", failure); std::fflush(screen); }
        if (logfile) { std::fprintf(logfile, "%s\n", failure); std::fflush(logfile); }
    }
    std::jmp_buf *back = armed;
    armed = nullptr;
    std::longjmp(*back, 1);
}

namespace LAMMPS_NS {

void Error::all(const char *file, int line, const char *str)
{
    if (armed) {
        char text[3900];
        std::snprintf(text, sizeof text, "%s (%s:%d)", str, file, line);
        fail_all(world, screen, logfile, text);
    }
    original<void (*)(Error *, const char *, int, const char *)>(
        "_ZN9LAMMPS_NS5Error3allEPKciS2_")(this, file, line, str);
    std::abort();
}

void Error::fix_error(const char *file, int line, Fix *fix, const char *str, const char *str2)
{
    if (armed) {
        char text[3900];
        // (the four-argument fix_error of libliggghts comes here through its PLT)
        if (std::strlen(str2) > 2)
            std::snprintf(text, sizeof text, "Fix %s (id %s): %s (%s:%d)", fix->style, fix->id, str2, file, line);
        else
            std::snprintf(text, sizeof text, "Illegal fix %s (id %s) command (%s:%d)", fix->style, fix->id, file, line);
        fail_all(world, screen, logfile, text);
    }
    original<void (*)(Error *, const char *, int, Fix *, const char *, const char *)>(
        "_ZN9LAMMPS_NS5Error9fix_errorEPKciPNS_3FixES2_S2_")(this, file, line, fix, str, str2);
    std::abort();
}

void Error::compute_error(const char *file, int line, Compute *compute, const char *str)
{
    if (armed) {
        char text[3900];
        std::snprintf(text, sizeof text, "Compute %s (id %s): %s (%s:%d)", compute->style, compute->id, str, file, line);
        fail_all(world, screen, logfile, text);
    }
    original<void (*)(Error *, const char *, int, Compute *, const char *)>(
        "_ZN9LAMMPS_NS5Error13compute_errorEPKciPNS_7ComputeES2_")(this, file, line, compute, str);
    std::abort();
}

// One rank alone: returns only when it is the only rank (the others would wait forever).
void Error::one(const char *file, int line, const char *str)
{
    int n;
    MPI_Comm_size(world, &n);
    if (armed && n == 1) {
        char text[3900];
        std::snprintf(text, sizeof text, "%s (%s:%d)", str, file, line);
        fail_all(world, screen, logfile, text);
    }
    // Under MPI the rank with the error may have no screen (only rank 0 writes one), and
    // MPI_Abort ends every rank: say it on this rank's stderr, with what the host was running.
    if (exit_log[0]) {
        int me;
        MPI_Comm_rank(world, &me);
        std::fprintf(stderr, "LIGGGHTS ended the process%s%s: ERROR on proc %d: %s (%s:%d)\n",
                     context[0] ? " at " : "", context, me, str, file, line);
        std::fflush(stderr);
        reported = true;
    }
    original<void (*)(Error *, const char *, int, const char *)>(
        "_ZN9LAMMPS_NS5Error3oneEPKciS2_")(this, file, line, str);
    std::abort();
}

}  // namespace LAMMPS_NS

extern "C" {

// One LIGGGHTS command (is_file != 0: an input file, as lammps_file): 0 when done, 1 when
// LIGGGHTS reported an error (its ERROR line from collheat_failure).
int collheat_command(void *ptr, const char *line, int is_file)
{
    std::jmp_buf back;
    if (setjmp(back)) return 1;
    armed = &back;
    failure[0] = 0;
    if (is_file) lammps_file(ptr, const_cast<char *>(line));
    else lammps_command(ptr, const_cast<char *>(line));
    armed = nullptr;
    return 0;
}

const char *collheat_failure() { return failure; }

// What the host runs now (e.g. "in.run:27 (run 5000)"), named if LIGGGHTS ends the process.
void collheat_context(const char *text)
{
    std::snprintf(context, sizeof context, "%s", text ? text : "");
}

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

// A forked copy's output from now on: its screen to another file (the parent's stream is
// left alone, its buffer was flushed before the fork), no log, and no dump or restart file
// written at a set-up (update->restrict_output, which Output::setup obeys): the copy shares
// the parent's open files, and a set-up after a reset_timestep would write the dump's frame
// of that step into them a second time, before the parent writes it.
int collheat_trial_output(void *ptr, const char *path)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    FILE *f = std::fopen(path, "w");
    if (!f) return -1;
    lmp->screen = f;
    lmp->logfile = nullptr;
    lmp->update->restrict_output = 1;
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

// LIGGGHTS' unit style now ("si", "cgs", "lj", ...: a units command, a restart file's, or the default).
const char *collheat_unit_style(void *ptr) { return static_cast<LAMMPS *>(ptr)->update->unit_style; }

// LIGGGHTS' atom style now (the script's atom_style, a restart file's, or the default atomic),
// and whether its atoms are plain spheres: a radius and a mass per atom (atom_style granular or
// sphere, alone or in a hybrid) and no shape of another kind (superquadric, ellipsoid, line,
// tri, body). SPH particles (atom_style sph) have neither radius nor per-atom mass.
const char *collheat_atom_style(void *ptr) { return static_cast<LAMMPS *>(ptr)->atom->atom_style; }

int collheat_sphere_atoms(void *ptr)
{
    const Atom *a = static_cast<LAMMPS *>(ptr)->atom;
    return a->sphere_flag && a->radius_flag && a->rmass_flag && !a->superquadric_flag && !a->ellipsoid_flag
           && !a->line_flag && !a->tri_flag && !a->body_flag;
}

// The interval [steps] of the script's most frequent dump with a fixed interval; 0 if none.
int collheat_dump_every(void *ptr)
{
    const Output *out = static_cast<LAMMPS *>(ptr)->output;
    int every = 0;
    for (int i = 0; i < out->ndump; ++i)
        if (out->every_dump[i] > 0 && (every == 0 || out->every_dump[i] < every)) every = out->every_dump[i];
    return every;
}

}

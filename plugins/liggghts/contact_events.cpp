// Contact events recorded inside LIGGGHTS at every DEM step, for pyhost/engines/events.py.
//
// The host adds `fix ID all external pf/callback 1 1073741824` and attaches a Recorder to it: LIGGGHTS
// then calls record() in post_force of every step (and of each run's set-up), after the
// forces, with x at the end of the step and v at the half step. record() walks the pair
// style's neighbour list, the primitive walls (with LIGGGHTS' own geometry) and the mesh walls
// and keeps the set of touching pairs (overlap r_i + r_j - |x_i - x_j| > 0, LIGGGHTS' own
// contact test). A contact that
// was not there on the previous call is a BEGIN event with its approach speed
// vn = -(v_i - v_j) . n [m/s] (n the unit normal from j to i; > 0 while closing in): at the
// first step in contact v is still the velocity before the contact, since the half-step
// velocity was updated with the forces of the step before, when they did not touch. A
// contact gone is an END event with its duration in steps. The host takes the events in
// batches (collheat_events_take). The fix adds no force: LIGGGHTS adds its array to the forces
// only at steps that are multiples of its napply (APPLY, 2^30 steps), where the callback zeroes
// it first; at other steps neither (zeroing and adding 27,000 atoms' array cost 0.1 ms a step).
//
// With a script's fix heat/gran (collheat_events_conduction), each new pair contact also keeps
// the flux heat/gran conducts through it at each of its first `window` steps, computed as
// FixHeatGranCond::post_force_eval does (flux into i = (T_j - T_i) 4 k_i k_j / (k_i + k_j)
// sqrt(A), A from the overlap, area-corrected, or constant, or projected): the host takes back
// what heat/gran moved during the collision's model time (pyhost.loop.Coupling.harvest). A
// history is handed over once full, or when its contact ends (collheat_events_histories).
// So does each new contact with a wall through which heat/gran conducts and whose collisions
// the host gives heat (collheat_events_wall_conduction: the wall's temperature, atom type and
// contact area mode, as fix wall/gran's addHeatFlux takes them: flux into the particle =
// (T_wall - T_i) 4 k_i k_w / (k_i + k_w) sqrt(A), A = pi (R^2 - (R - delta)^2) from the overlap
// delta (area-corrected as heat/gran corrects), or constant, or projected; on a mesh, through
// its deepest triangle).
//
// With heat/gran the recorder also sums, at every step (not at a run's set-up), what its
// transport equation adds to the particles' m c Temp when it integrates (final_integrate, after
// this fix's post_force; FixScalarTransportEquation::advanceQtyExplicit, and
// advanceQtyImplicit's Crank-Nicolson form): the script's sources, per-atom heatSource [W] *
// nevery * dt, and its conduction, heatFlux [W] * dt, whose pair terms cancel, so that its sum
// is what heat/gran's walls with a temperature conducted in. The host's energy balance counts
// them as heat_from_sources and heat_from_script_walls (collheat_events_heat_gran_heat).
//
// With restitution feedback the host gives each open contact the normal separation speed the
// heat model's restitution asks for (collheat_events_restitution); at the step the contact
// ends the recorder imposes it on the pair's normal velocity, conserving momentum (as
// pyhost.contact_heat.restitution_impulse), and flags the END.
//
// Keys as pyhost.collisions.contact_keys: (smaller id << 31) | larger id, a wall being
// WALL_BASE + its index (> every particle id). Under MPI each rank has its own recorder and a
// pair is recorded by the rank that owns the atom of the smaller id (a wall contact by the
// atom's owner). An open contact whose atom moves to another rank (at a neighbour build, where
// LIGGGHTS exchanges atoms) ends on the old rank and begins on the new one at that step: the
// END says MOVED (its atom is no longer here) and every BEGIN at a build says MOVED (it may
// have come from another rank); the host pairs them by key and step (pyhost.engines.events
// .join_moved), and what is left of either is a real event.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <vector>
#include "lammps.h"
#include "atom.h"
#include "force.h"
#include "pair.h"
#include "neigh_list.h"
#include "modify.h"
#include "fix_external.h"
#include "update.h"
#include "neighbor.h"
#include "fix_mesh_surface.h"
#include "primitive_wall.h"
#include "fix_neighlist_mesh.h"
#include "fix_contact_history_mesh.h"
#include "tri_mesh.h"
#include "domain.h"
#include "fix_property_atom.h"
#include "comm.h"
#include "fix_property_global.h"
#define protected public
#include "fix_heat_gran_conduction.h"
#include "fix_scalar_transport_equation.h"
#undef protected

// LIGGGHTS' fix wall/gran, of which the recorder calls one method: its header needs headers
// Debian does not ship (style_surface_model.h), so the method is declared here. Fix is the
// class's first base, so a Fix pointer to one is a pointer to it; the method is exported by
// libliggghts (LAMMPS_NS::FixWallGran::primitiveWall(), null for a mesh wall).
namespace LAMMPS_NS {
class FixWallGran : public Fix {
public:
    PrimitiveWall *primitiveWall();
};
}

using namespace LAMMPS_NS;

namespace {

enum Kind { PAIR_BEGIN = 0, PAIR_END = 1, WALL_BEGIN = 2, WALL_END = 3 };
constexpr int ROW = 12; // kind, step, i, j, vn [m/s], nx, ny, nz, duration [steps], T_i, T_j [K] at the begin,
                        // and flags: IMPOSED (an END's separation speed was imposed), MOVED (see above)
constexpr double IMPOSED = 1.0, MOVED = 2.0;
constexpr int HEAD = 4; // a flux history: i, j (ids, i < j), step of the begin, steps kept; then the fluxes
enum Area { OVERLAP = 0, CONSTANT = 1, PROJECTION = 2 };   // FixHeatGranCond's contact area modes

struct WallHeat {                              // a wall heat/gran conducts through: its temperature [K]
    double T;                                  // (< 0: none, or its collisions get no host heat), atom type,
    int type, mode;                            // contact area mode (Area) and constant area [m^2]
    double area;
};

struct History {                               // a new pair (or wall) contact's heat/gran flux [W] into i, per step
    uint64_t key;
    bigint start;
    int filled;
    std::vector<double> flux;
};

struct Recorder {
    LAMMPS *lmp;
    FixExternal *fix;
    bool primed = false;                       // false: the next call records contacts, no events
    std::vector<double> rows;                  // events waiting, ROW doubles each
    std::vector<FixWallGran *> prims;          // primitive walls: their fix wall/gran and the partner
    std::vector<double> prim_code;             // code the host gives their contacts
    std::vector<FixMeshSurface *> meshes;       // mesh walls: the fix mesh/surface and the code
    std::vector<double> mesh_code;             // of its contacts (one per particle and mesh: the deepest)
    std::vector<WallHeat> prim_heat, mesh_heat; // with heat/gran: the walls it conducts through (as prims, meshes)
    std::vector<double> depth, normal;         // per local atom, this call and mesh: overlap [m] and normal,
    std::vector<int> deepest;                  // and the deepest triangle (meshes without a contact history)
    bool new_walls = false;                   // walls given since the last call: what touches them is open
    long long begun = 0, ended = 0;
    int meshes_by_history = 0;                 // meshes read from LIGGGHTS' contact history at the last call
    struct Target { double speed, n[3]; };     // separation speed [m/s] to impose at the end; a wall's normal
    std::unordered_map<uint64_t, Target> targets;
    FixHeatGranCond *conduction = nullptr;     // a script's fix heat/gran, or none
    int window = 0;                            // steps of flux kept per new pair contact
    std::vector<History> histories;            // in use or free (free: start < 0)
    std::vector<int> free_histories;
    std::vector<double> done;                  // histories handed over: HEAD + window doubles each
    tagint max_tag = -1;                       // with heat/gran: the largest id seen, and each new
    std::vector<double> appeared;              // atom's id, Temp at its first step (before heat/gran moves any)
                                               // and that step (under MPI an atom that moves in may be
                                               // larger than all this rank saw: the host keeps the first)
    double source_heat = 0.0;                  // with heat/gran: what its sources put in since the last take [J]
    double flux_heat = 0.0;                    // and what its conduction did (its walls' share) [J]
    std::vector<double> capacity;              // heat/gran's thermalCapacity by atom type (scratch)
    bool syncing = false;                      // record() called by the host between runs, not by a step

    // The state of the contacts, laid out like the neighbour list (one slot per entry, in
    // the order of ilist and each atom's neighbours) and, for the walls, like the local
    // atoms (wall-major). Both layouts hold from one neighbour build to the next (LIGGGHTS
    // sorts, exchanges, inserts and deletes atoms only before a build), so between builds a
    // step costs a distance test per neighbour and no lookup. At a build, the open contacts
    // are carried over by key.
    bigint layout = -1;                        // neighbor->ncalls of the layout,
    bigint layout_last = -1;                   // neighbor->lastcall (init() starts ncalls again),
    const NeighList *layout_list = nullptr;    // the list and its atoms
    int layout_inum = -1;
    size_t walls_laid = 0;                    // walls and local atoms in the layout
    int nlocal_laid = -1;
    std::vector<uint8_t> touch;                // in contact at the last call
    std::vector<bigint> since;                 // step of the first call in contact
    std::vector<uint64_t> key;                 // the contact's key
    std::vector<int> history;                  // its flux history (index into histories), or -1
    std::unordered_map<uint64_t, std::pair<bigint, int>> carry;

    void event(int kind, bigint step, double i, double j, double vn, const double *n, double duration,
               double Ti = NAN, double Tj = NAN, double imposed = 0.0)
    {
        const double row[ROW] = {double(kind), double(step), i, j, vn, n[0], n[1], n[2], duration, Ti, Tj, imposed};
        rows.insert(rows.end(), row, row + ROW);
    }

    // Slot k in contact now (its key k_, ids i and j, local atoms li and lj (-1: a wall),
    // approach speed vn, normal n). With heat/gran, a BEGIN carries the two temperatures of
    // that step: heat/gran changes them before the host takes the event.
    inline void on(size_t k, bigint step, bool rebuilt, int kind, uint64_t k_, double i, double j, int li, int lj,
                   double vn, const double *n, bool quiet = false, bool conducts = false)
    {
        if (touch[k] && !rebuilt) return;
        touch[k] = 1;
        key[k] = k_;
        history[k] = -1;
        if (rebuilt) {
            auto it = carry.find(k_);
            if (it != carry.end()) {
                since[k] = it->second.first;
                history[k] = it->second.second;
                carry.erase(it);
                return;
            }
        }
        since[k] = step;
        if (primed && !quiet) {
            const double *T = conduction ? conduction->Temp : nullptr;
            event(kind, step, i, j, vn, n, 0.0, T ? T[li] : NAN, T && lj >= 0 ? T[lj] : NAN,
                  rebuilt && lmp->comm->nprocs > 1 ? MOVED : 0.0);
            ++begun;
            if (conduction && (kind == PAIR_BEGIN || conducts)) history[k] = open_history(k_, step);
        }
    }

    int open_history(uint64_t k_, bigint step)
    {
        int h;
        if (free_histories.empty()) { h = int(histories.size()); histories.push_back(History()); }
        else { h = free_histories.back(); free_histories.pop_back(); }
        History &y = histories[h];
        y.key = k_;
        y.start = step;
        y.filled = 0;
        y.flux.assign(window, 0.0);
        return h;
    }

    // Hand history h over (full, or its contact ended) and free it.
    void close_history(int h)
    {
        History &y = histories[h];
        const double head[HEAD] = {double(y.key >> 31), double(y.key & ((uint64_t(1) << 31) - 1)), double(y.start),
                                   double(y.filled)};
        done.insert(done.end(), head, head + HEAD);
        done.insert(done.end(), y.flux.begin(), y.flux.end());
        y.start = -1;
        free_histories.push_back(h);
    }

    // heat/gran's flux [W] into local or ghost atom i from j now (FixHeatGranCond::post_force_eval).
    double heat_gran_flux(int i, int j, double rsq) const
    {
        const double *r = lmp->atom->radius;
        const int *type = lmp->atom->type;
        const double radi = r[i], radj = r[j], radsum = radi + radj;
        double area;
        if (conduction->area_calculation_mode_ == CONSTANT)
            area = conduction->fixed_contact_area_;
        else if (conduction->area_calculation_mode_ == PROJECTION)
            area = M_PI * std::max(radi, radj) * std::max(radi, radj);
        else {
            double dist = std::sqrt(rsq);
            if (conduction->area_correction_flag_)
                dist = radsum - (radsum - dist) * conduction->deltan_ratio_[type[i] - 1][type[j] - 1];
            area = -M_PI / 4 * ((dist - radi - radj) * (dist + radi - radj) * (dist - radi + radj) * (dist + radi + radj)) /
                   (dist * dist);
        }
        const double ki = conduction->conductivity_[type[i] - 1], kj = conduction->conductivity_[type[j] - 1];
        const double hc = (ki > 0 && kj > 0) ? 4. * ki * kj / (ki + kj) * std::sqrt(area) : 0.0;
        return (conduction->Temp[j] - conduction->Temp[i]) * hc;
    }

    // heat/gran's flux [W] into local atom i from wall h now, at overlap delta [m]
    // (FixWallGran::addHeatFlux; its conductivities are heat/gran's thermalConductivity).
    double wall_flux(int i, double delta, const WallHeat &h) const
    {
        const double R = lmp->atom->radius[i];
        const int type = lmp->atom->type[i];
        double area;
        if (h.mode == CONSTANT)
            area = h.area;
        else if (h.mode == PROJECTION)
            area = M_PI * R * R;
        else {
            if (conduction->area_correction_flag_ && conduction->deltan_ratio_)
                delta *= conduction->deltan_ratio_[type - 1][h.type - 1];
            const double r = R - delta;
            area = (R * R - r * r) * M_PI;
        }
        const double kp = conduction->conductivity_[type - 1], kw = conduction->conductivity_[h.type - 1];
        const double SMALL = 1e-12;                        // (fix_wall_gran.cpp's)
        const double hc = (std::fabs(kp) < SMALL || std::fabs(kw) < SMALL) ? 0.0 : 4. * kp * kw / (kp + kw) * std::sqrt(area);
        return (h.T - conduction->Temp[i]) * hc;
    }

    // Slot k's flux at this step, into the smaller id (a wall's: into the particle), kept in its history.
    void keep(size_t k, double into_lo, bigint step)
    {
        History &y = histories[history[k]];
        const bigint age = step - y.start;
        if (age < 0 || age >= window) return;
        y.flux[age] = into_lo;
        y.filled = int(age) + 1;
        if (y.filled == window) { close_history(history[k]); history[k] = -1; }
    }

    // Slot k (atoms i, j in contact now, |x_i - x_j|^2 = rsq): its flux at this step into the smaller id.
    void conduct(size_t k, int i, int j, double rsq, bigint step)
    {
        const double into_i = heat_gran_flux(i, j, rsq);
        keep(k, lmp->atom->tag[i] < lmp->atom->tag[j] ? into_i : -into_i, step);
    }

    bool conducts(const std::vector<WallHeat> &heat, size_t w) const
    {
        return conduction && w < heat.size() && heat[w].T >= 0;
    }

    // Slot k not in contact now: an END if it was (between builds; at a build, what is left
    // in ``carry`` has ended).
    inline void off(size_t k, bigint step, bool rebuilt)
    {
        if (!touch[k]) return;
        touch[k] = 0;
        if (!rebuilt) {
            end(key[k], since[k], step);
            if (history[k] >= 0) { close_history(history[k]); history[k] = -1; }
        }
    }

    // ``moved``: its atom left this rank (a build under MPI; the contact may go on elsewhere).
    void end(uint64_t k_, bigint start, bigint step, bool moved = false)
    {
        if (!primed) return;
        const uint64_t lo = k_ >> 31, hi = k_ & ((uint64_t(1) << 31) - 1);
        const bool wall = hi >= (uint64_t(1) << 30);
        const double none[3] = {0, 0, 0};
        const bool imposed = !moved && !targets.empty() && impose(k_);
        event(wall ? WALL_END : PAIR_END, step, double(lo), double(hi), 0.0, none, double(step - start), NAN, NAN,
              (imposed ? IMPOSED : 0.0) + (moved ? MOVED : 0.0));
        ++ended;
    }

    // Whether the atom of this id is one of this rank's own (a deleted atom's id may lie beyond
    // LIGGGHTS' map).
    bool local(tagint id) const
    {
        Atom *atom = lmp->atom;
        if (id < 1 || id > atom->map_tag_max) return false;
        const int m = atom->map(id);
        return m >= 0 && m < atom->nlocal;
    }

    // The separation speed asked for contact k_ (if the host gave one) imposed now on the normal
    // velocity of its pair (the line of centres, nearest image) or particle (a wall: the normal
    // at its begin), momentum conserved. False if there is none, or an atom is not local here.
    bool impose(uint64_t k_)
    {
        auto it = targets.find(k_);
        if (it == targets.end()) return false;
        const Target t = it->second;
        targets.erase(it);
        Atom *atom = lmp->atom;
        const tagint lo = tagint(k_ >> 31), hi = tagint(k_ & ((uint64_t(1) << 31) - 1));
        const bool wall = hi >= (tagint(1) << 30);
        if (!local(lo) || (!wall && !local(hi))) return false;
        const int a = atom->map(lo), b = wall ? -1 : atom->map(hi);
        double **x = atom->x, **v = atom->v;
        const double *m = atom->rmass;
        double n[3] = {t.n[0], t.n[1], t.n[2]};
        if (!wall) {
            double d[3] = {x[a][0] - x[b][0], x[a][1] - x[b][1], x[a][2] - x[b][2]};
            lmp->domain->minimum_image(d);
            const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(len > 0)) return false;
            for (int c = 0; c < 3; ++c) n[c] = d[c] / len;
        }
        const double vb[3] = {wall ? 0.0 : v[b][0], wall ? 0.0 : v[b][1], wall ? 0.0 : v[b][2]};
        const double separation = (v[a][0] - vb[0]) * n[0] + (v[a][1] - vb[1]) * n[1] + (v[a][2] - vb[2]) * n[2];
        const double change = t.speed - separation;
        const double share_a = wall ? 1.0 : m[b] / (m[a] + m[b]), share_b = wall ? 0.0 : m[a] / (m[a] + m[b]);
        for (int c = 0; c < 3; ++c) {
            v[a][c] += share_a * change * n[c];
            if (!wall) v[b][c] -= share_b * change * n[c];
        }
        return true;
    }

    // Particle p (local) against triangle t: true if they touch (LIGGGHTS' test), with the
    // overlap dn < 0 [m] and the unit normal from the wall to the particle.
    bool tri_contact(TriMesh *mesh, int p, int t, double &dn, double *n) const
    {
        double **x = lmp->atom->x;
        double delta[3];
        int barysign;
        dn = mesh->resolveTriSphereContact(p, t, lmp->atom->radius[p], x[p], delta, barysign);
        if (dn >= 0) return false;
        double node0[3];
        mesh->node(t, 0, node0);
        const double len = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
        double s = len > 0 ? 1.0 / len : 0.0;
        if ((x[p][0] - node0[0]) * delta[0] + (x[p][1] - node0[1]) * delta[1] + (x[p][2] - node0[2]) * delta[2] < 0)
            s = -s;
        n[0] = delta[0] * s; n[1] = delta[1] * s; n[2] = delta[2] * s;
        return true;
    }

    // Slot k: particle i touching mesh m, deepest on triangle t with normal n: the approach
    // speed relative to the wall at the contact point.
    void begin_on_mesh(size_t k, bigint step, bool rebuilt, size_t m, TriMesh *mesh, int i, int t, const double *n)
    {
        double **x = lmp->atom->x, **v = lmp->atom->v;
        double vw[3] = {0, 0, 0};
        MultiVectorContainer<double, 3, 3> *moving = mesh->prop().getElementProperty<MultiVectorContainer<double, 3, 3> >("v");
        if (moving) {
            double point[3], bary[3];
            int barysign;
            mesh->resolveTriSphereContactBary(i, t, lmp->atom->radius[i], x[i], point, bary, barysign);
            double ***node_v = moving->begin();
            for (int c = 0; c < 3; ++c)
                vw[c] = bary[0] * node_v[t][0][c] + bary[1] * node_v[t][1][c] + bary[2] * node_v[t][2][c];
        }
        const double vn = -((v[i][0] - vw[0]) * n[0] + (v[i][1] - vw[1]) * n[1] + (v[i][2] - vw[2]) * n[2]);
        const int *tag = lmp->atom->tag;
        on(k, step, rebuilt, WALL_BEGIN, (uint64_t(tag[i]) << 31) | uint64_t(mesh_code[m]), tag[i], mesh_code[m],
           i, -1, vn, n, new_walls, conducts(mesh_heat, m));
    }

    // Particle i's deepest partner triangle in mesh m's contact history: its index (-1: none
    // touches), overlap dn < 0 [m] and normal.
    int deepest_partner(FixContactHistoryMesh *hist, TriMesh *mesh, int i, double &best, double *n) const
    {
        int t_best = -1;
        best = 0;
        for (int j = 0; j < hist->nneighs(i); ++j) {
            const int id = hist->get_partner_idTri(i, j);
            if (id < 0) continue;
            for (int c = 0; c < mesh->map_size(id); ++c) {
                const int t = mesh->map(id, c);
                if (t < 0) continue;
                double dn, nt[3];
                if (!tri_contact(mesh, i, t, dn, nt)) continue;
                if (t_best < 0 || dn < best) { best = dn; t_best = t; n[0] = nt[0]; n[1] = nt[1]; n[2] = nt[2]; }
                break;
            }
        }
        return t_best;
    }

    // Whether every fix wall/gran comes before this fix: their post_force (and the mesh
    // contact histories it keeps) ran this step before the recorder's.
    bool walls_before_me() const
    {
        const Modify *modify = lmp->modify;
        int me = -1, last_wall = -1;
        for (int f = 0; f < modify->nfix; ++f) {
            if (modify->fix[f] == fix) me = f;
            else if (std::strncmp(modify->fix[f]->style, "wall/gran", 9) == 0) last_wall = f;
        }
        return me > last_wall;
    }

    // Whether fix number f of LIGGGHTS comes after the recorder's (its set-up, which builds a
    // primitive wall's list of nearby particles, then runs after the recorder's).
    bool after_me(const Fix *f) const
    {
        const Modify *modify = lmp->modify;
        for (int k = 0; k < modify->nfix; ++k) {
            if (modify->fix[k] == fix) return true;
            if (modify->fix[k] == f) return false;
        }
        return false;
    }

    // What heat/gran's transport equation adds to this rank's atoms' m c Temp at this step [J],
    // added to source_sum (its sources) and flux_sum (its conduction flux): over the atoms it
    // integrates, as it integrates them (its group, nevery, capacity test).
    void heat_gran_now(bigint step, double &source_sum, double &flux_sum)
    {
        const FixScalarTransportEquation *ste = conduction->fix_ste;
        if (!ste || !ste->int_flag || !ste->fix_source || !ste->fix_flux || step % ste->nevery_) return;
        const double *source = ste->fix_source->vector_atom, *flux = ste->fix_flux->vector_atom;
        const Atom *atom = lmp->atom;
        const int nlocal = atom->nlocal;
        const double dt = lmp->update->dt, SMALL = 1e-8;      // (fix_scalar_transport_equation.cpp's)
        capacity.assign(atom->ntypes + 1, 1.0);               // without a capacity Temp takes q dt
        if (ste->capacity_flag)
            for (int t = 1; t <= atom->ntypes; ++t) capacity[t] = ste->fix_capacity->compute_vector(t - 1);
        for (int i = 0; i < nlocal; ++i) {
            if (!(atom->mask[i] & ste->groupbit) || (source[i] == 0.0 && flux[i] == 0.0)) continue;
            const double c = capacity[atom->type[i]];
            if (ste->capacity_flag && std::fabs(c) <= SMALL) continue;
            const double mc = ste->capacity_flag ? atom->rmass[i] * c : 1.0;
            double scale = dt;
            if (ste->implicitMode_ && ste->fix_transCoeffQty_) {    // the implicit form divides the step's change
                const double r = atom->radius[i];
                const double termMP = dt / mc * ste->fix_transCoeffQty_->vector_atom[i] * r * r * 12.5663706144;
                scale /= 1.0 + termMP * ste->crankNicholsonFactor_;
            }
            source_sum += source[i] * double(ste->nevery_) * scale;
            flux_sum += flux[i] * scale;
        }
    }

    void record(bigint step)
    {
        Atom *atom = lmp->atom;
        const int nlocal = atom->nlocal;
        double **x = atom->x, **v = atom->v;
        const double *r = atom->radius;
        const int *tag = atom->tag;
        Pair *pair = lmp->force->pair;
        NeighList *list = pair ? pair->list : nullptr;
        const bool have_list = list && list->ilist;
        // a new layout at each neighbour build (or new walls): the slots counted then only
        const size_t walls = prims.size() + meshes.size();
        // (a run's set-up calls Neighbor::init, which counts builds from 0 again: the step of
        // the last build and the list itself tell a build that ncalls alone misses)
        const Neighbor *nb = lmp->neighbor;
        const bool rebuilt = nb->ncalls != layout || nb->lastcall != layout_last || walls != walls_laid ||
                             nlocal != nlocal_laid || (have_list && (list != layout_list || list->inum != layout_inum));
        if (rebuilt) {                         // the open contacts, by key, into the new layout
            size_t slots = 0;
            if (have_list)
                for (int ii = 0; ii < list->inum; ++ii) slots += list->numneigh[list->ilist[ii]];
            slots += walls * size_t(nlocal);
            walls_laid = walls;
            nlocal_laid = nlocal;
            carry.clear();
            for (size_t k = 0; k < touch.size(); ++k)
                if (touch[k]) carry.emplace(key[k], std::make_pair(since[k], history[k]));
            touch.assign(slots, 0);
            since.resize(slots);
            key.resize(slots);
            history.assign(slots, -1);
            layout = nb->ncalls;
            layout_last = nb->lastcall;
            layout_list = have_list ? list : nullptr;
            layout_inum = have_list ? list->inum : -1;
        }
        size_t k = 0;
        if (conduction) {
            if (!lmp->update->setupflag && !syncing) heat_gran_now(step, source_heat, flux_heat);
            conduction->updatePtrs();                       // its Temp, after any insertion
            tagint top = max_tag;
            for (int i = 0; i < nlocal; ++i)
                if (tag[i] > max_tag) {
                    if (primed && max_tag >= 0) {
                        appeared.push_back(double(tag[i]));
                        appeared.push_back(conduction->Temp[i]);
                        appeared.push_back(double(step));
                    }
                    top = std::max(top, tag[i]);
                }
            max_tag = top;
        }
        if (have_list) {
            NeighList *hist = pair->listgranhistory;        // LIGGGHTS' own contact flags, if it keeps them
            const bool flags = hist && hist->firstneigh && !rebuilt;
            for (int ii = 0; ii < list->inum; ++ii) {
                const int i = list->ilist[ii];
                const int *jlist = list->firstneigh[i];
                const int jnum = list->numneigh[i];
                const int *flag = flags ? hist->firstneigh[i] : nullptr;
                for (int jj = 0; jj < jnum; ++jj, ++k) {
                    // between builds, a pair LIGGGHTS holds apart now and held apart before needs no test
                    if (flag && !flag[jj] && !touch[k]) continue;
                    const int j = jlist[jj] & NEIGHMASK;
                    const double d[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
                    const double rsq = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    const double radsum = r[i] + r[j];
                    // recorded once: a pair of two local atoms as listed; a pair with a ghost (an
                    // atom of another rank, or a periodic image) by the owner of the smaller id
                    if (rsq >= radsum * radsum || (j >= nlocal && tag[i] > tag[j])) { off(k, step, rebuilt); continue; }
                    if (!touch[k] || rebuilt) {
                        const bool i_first = tag[i] < tag[j];
                        const int lo = i_first ? i : j, hi = i_first ? j : i;
                        const double dist = std::sqrt(rsq);
                        const double s = (i_first ? 1.0 : -1.0) / (dist > 0 ? dist : 1.0);
                        const double n[3] = {d[0] * s, d[1] * s, d[2] * s};       // from hi to lo
                        const double vn = -((v[lo][0] - v[hi][0]) * n[0] + (v[lo][1] - v[hi][1]) * n[1] +
                                            (v[lo][2] - v[hi][2]) * n[2]);
                        on(k, step, rebuilt, PAIR_BEGIN, (uint64_t(tag[lo]) << 31) | uint64_t(tag[hi]),
                           tag[lo], tag[hi], lo, hi, vn, n);
                    }
                    if (history[k] >= 0) conduct(k, i, j, rsq, step);
                }
            }
        }
        // primitive walls (planes, cylinders), with LIGGGHTS' own geometry and list: fix wall/gran
        // lists the particles within the skin of its wall at each neighbour build, and tests only
        // those, and only of its group (PrimitiveWall::resolveContact: distance - radius <= 0 is a
        // contact). Between two builds no listed particle leaves the list, and none unlisted can
        // reach the wall (neigh_modify's check), so a contact ends while listed. delta points from
        // the centre to the wall; the normal from the wall to the particle is -delta / |delta|.
        for (size_t w = 0; w < prims.size(); ++w, k += nlocal) {
            PrimitiveWall *wall = prims[w]->primitiveWall();
            if (rebuilt && after_me(prims[w]))         // at a set-up its list is made after this call
                wall->buildNeighList(lmp->neighbor->skin, x, atom->radius, nlocal);
            const int groupbit = prims[w]->groupbit, *mask = atom->mask;
            int *near = nullptr;
            const int nnear = wall->getNeighbors(near);
            for (int c = 0; c < nnear; ++c) {
                const int i = near[c];
                if (i >= nlocal) continue;
                const size_t kk = k + i;
                double delta[3] = {0, 0, 0}, dn = 1.0;
                if (!(mask[i] & groupbit) || (dn = wall->resolveContact(x[i], r[i], delta)) > 0) { off(kk, step, rebuilt); continue; }
                if (!touch[kk] || rebuilt) {
                    const double len = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
                    const double d = len > 0 ? -len : 1.0;      // (a division: a plane's normal is +-1 exactly)
                    const double n[3] = {delta[0] / d, delta[1] / d, delta[2] / d};
                    on(kk, step, rebuilt, WALL_BEGIN, (uint64_t(tag[i]) << 31) | uint64_t(prim_code[w]), tag[i],
                       prim_code[w], i, -1, -(v[i][0] * n[0] + v[i][1] * n[1] + v[i][2] * n[2]), n, new_walls,
                       conducts(prim_heat, w));
                }
                if (history[kk] >= 0) keep(kk, wall_flux(i, -dn, prim_heat[w]), step);
            }
        }
        // mesh walls. Where LIGGGHTS keeps a contact history of the mesh (fix wall/gran with
        // tangential history) and its wall/gran fixes come before this fix (their post_force
        // ran this step), the particles in contact are those with a partner triangle there
        // (fix wall/gran's own test, deltan <= 0, kept by FixContactHistoryMesh): one integer
        // per particle and step, and the geometry only for a contact that begins. Otherwise
        // LIGGGHTS' own candidates of each triangle and its own contact test
        // (TriMesh::resolveTriSphereContact: distance - radius < 0). Either way the deepest
        // triangle gives the normal, turned to point from the wall to the particle. A moving
        // mesh (fix move/mesh) gives the wall's velocity at the contact point, as fix wall/gran
        // takes it: its triangle's node velocities weighted by the point's barycentric
        // coordinates; the approach speed is the relative one.
        const bool walls_first = !meshes.empty() && walls_before_me();
        meshes_by_history = 0;
        for (size_t m = 0; m < meshes.size(); ++m) {
            TriMesh *mesh = meshes[m]->triMesh();
            FixNeighlistMesh *near = meshes[m]->meshNeighlist();
            FixContactHistoryMesh *hist = meshes[m]->contactHistory();
            if (!near) continue;
            if (walls_first && hist && lmp->neighbor->contactDistanceFactor <= 1.0) {
                ++meshes_by_history;
                for (int i = 0; i < nlocal; ++i, ++k) {
                    if (hist->n_partner(i) == 0) { off(k, step, rebuilt); continue; }
                    const uint64_t key_ = (uint64_t(tag[i]) << 31) | uint64_t(mesh_code[m]);
                    double best = 0, n[3] = {0, 0, 0};
                    if ((touch[k] && !rebuilt) || (rebuilt && carry.count(key_))) {     // open (before the build)
                        const double zero[3] = {0, 0, 0};
                        if (rebuilt) on(k, step, rebuilt, WALL_BEGIN, key_, tag[i], mesh_code[m], i, -1, 0.0, zero);
                        if (history[k] >= 0 && deepest_partner(hist, mesh, i, best, n) >= 0)
                            keep(k, wall_flux(i, -best, mesh_heat[m]), step);
                        continue;
                    }
                    const int t_best = deepest_partner(hist, mesh, i, best, n);
                    if (t_best < 0) { off(k, step, rebuilt); continue; }    // (a partner LIGGGHTS has not cleaned up)
                    begin_on_mesh(k, step, rebuilt, m, mesh, i, t_best, n);
                    if (history[k] >= 0) keep(k, wall_flux(i, -best, mesh_heat[m]), step);
                }
                continue;
            }
            if (depth.size() < size_t(nlocal)) { depth.resize(nlocal); normal.resize(3 * size_t(nlocal)); deepest.resize(nlocal); }
            std::fill(depth.begin(), depth.begin() + nlocal, 0.0);
            const int ntri = mesh->sizeLocal() + mesh->sizeGhost();
            for (int t = 0; t < ntri; ++t) {
                const std::vector<int> &cand = near->get_contact_list(t);
                for (int p : cand) {
                    if (p >= nlocal) continue;
                    double dn, nt[3];
                    if (!tri_contact(mesh, p, t, dn, nt) || dn >= depth[p]) continue;
                    depth[p] = dn;
                    deepest[p] = t;
                    normal[3 * p] = nt[0]; normal[3 * p + 1] = nt[1]; normal[3 * p + 2] = nt[2];
                }
            }
            for (int i = 0; i < nlocal; ++i, ++k) {
                if (depth[i] >= 0) { off(k, step, rebuilt); continue; }
                if (!touch[k] || rebuilt) begin_on_mesh(k, step, rebuilt, m, mesh, i, deepest[i], &normal[3 * i]);
                if (history[k] >= 0) keep(k, wall_flux(i, -depth[i], mesh_heat[m]), step);
            }
        }
        if (rebuilt) {                         // contacts of the old layout not found again: ended
            for (const auto &c : carry) {
                end(c.first, c.second.first, step, lmp->comm->nprocs > 1 && !local(tagint(c.first >> 31)));
                if (c.second.second >= 0) close_history(c.second.second);
            }
            carry.clear();
        }
        primed = true;
        new_walls = false;
    }

    long long open_count() const
    {
        long long n = 0;
        for (uint8_t t : touch) n += t;
        return n;
    }
};

}  // namespace

namespace {

constexpr bigint APPLY = bigint(1) << 30;     // the fix's napply (pyhost.engines.events.APPLY)

void callback(void *ptr, bigint step, int nlocal, int *, double **, double **f)
{
    Recorder *rec = static_cast<Recorder *>(ptr);
    if (step % APPLY == 0 && nlocal > 0 && f)      // LIGGGHTS adds the array now: it adds no force
        std::memset(f[0], 0, sizeof(double) * 3 * nlocal);
    rec->record(step);
}

// The walls of one kind: the fixes of these n ids, each of a style beginning with `style` and
// usable (`usable`), with their partner codes, become the recorder's `fixes` and `codes`.
// Returns n, or -1 if one is not such a fix (nothing changed then). Walls given anew: the
// particles touching them then are in contact, not colliding (as those touching anything at
// the start); the same walls again (at each run of a script) change nothing.
template <class F, class Usable>
int set_walls(Recorder *rec, int n, const char **ids, const double *code, const char *style, Usable usable,
              std::vector<F *> &fixes, std::vector<double> &codes)
{
    std::vector<F *> found;
    for (int k = 0; k < n; ++k) {
        const int f = rec->lmp->modify->find_fix(ids[k]);
        if (f < 0 || std::strncmp(rec->lmp->modify->fix[f]->style, style, std::strlen(style)) != 0) return -1;
        F *wall = static_cast<F *>(rec->lmp->modify->fix[f]);
        if (!usable(wall)) return -1;
        found.push_back(wall);
    }
    if (found == fixes && std::vector<double>(code, code + n) == codes) return n;
    fixes = found;
    codes.assign(code, code + n);
    rec->new_walls = true;
    return n;
}

}  // namespace

extern "C" {

// Attach a Recorder to `fix <fix_id> all external pf/callback 1 1073741824`; null if there is no such fix.
void *collheat_events_attach(void *ptr, const char *fix_id)
{
    LAMMPS *lmp = static_cast<LAMMPS *>(ptr);
    int k = lmp->modify->find_fix(fix_id);
    if (k < 0 || std::strcmp(lmp->modify->fix[k]->style, "external") != 0) return nullptr;
    Recorder *rec = new Recorder;
    rec->lmp = lmp;
    rec->fix = static_cast<FixExternal *>(lmp->modify->fix[k]);
    rec->fix->set_callback(callback, rec);
    return rec;
}

// Whether a fix wall/gran comes after the recorder's fix (a script's wall defined after the
// first run, where the host added the recorder): its post_force, which adds its heat/gran flux
// to heatFlux, runs after the recorder's, whose sum of that flux would miss it.
int collheat_events_walls_after(void *handle) { return !static_cast<Recorder *>(handle)->walls_before_me(); }

// The recorder goes on with another `fix external pf/callback` (its fix given anew, after the
// walls: pyhost.engines.events.ContactEvents.keep_last); its contacts and histories stay.
// -1 if there is no such fix.
int collheat_events_reattach(void *handle, const char *fix_id)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    const int k = rec->lmp->modify->find_fix(fix_id);
    if (k < 0 || std::strcmp(rec->lmp->modify->fix[k]->style, "external") != 0) return -1;
    rec->fix = static_cast<FixExternal *>(rec->lmp->modify->fix[k]);
    rec->fix->set_callback(callback, rec);
    return 0;
}

// The primitive walls: n `fix wall/gran ... primitive` ids and the partner code of their
// contacts (WALL_BASE + the host's wall index); -1 if one is not such a fix.
int collheat_events_primitives(void *handle, int n, const char **ids, const double *code)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    return set_walls(rec, n, ids, code, "wall/gran", [](FixWallGran *w) { return w->primitiveWall() != nullptr; },
                     rec->prims, rec->prim_code);
}

// The host's mesh walls: n `fix mesh/surface` ids and the partner code of each; -1 if one has
// no neighbour list (a mesh used by no fix wall/gran).
int collheat_events_meshes(void *handle, int n, const char **ids, const double *code)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    return set_walls(rec, n, ids, code, "mesh/surface", [](FixMeshSurface *m) { return m->meshNeighlist() != nullptr; },
                     rec->meshes, rec->mesh_code);
}

// The next call records the contacts present as open, with no BEGIN events (a start or restart).
void collheat_events_prime(void *handle) { static_cast<Recorder *>(handle)->primed = false; }

// Record now, between runs, right after a set-up (its neighbour lists hold): walls given since
// then take the contacts present as open, so that a contact beginning at the next step is an
// event. (Otherwise the next call would take it: the first step after a restart, whose run
// does no set-up that would call the recorder.)
void collheat_events_sync(void *handle)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    rec->syncing = true;
    rec->record(rec->lmp->update->ntimestep);
    rec->syncing = false;
}

// Keep heat/gran's flux through each new pair contact for its first `window` steps: `fix_id`
// is the script's fix heat/gran. Returns 0, or -1 if that fix is not a heat/gran conduction.
int collheat_events_conduction(void *handle, const char *fix_id, int window)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    const int f = rec->lmp->modify->find_fix(fix_id);
    if (f < 0 || std::strncmp(rec->lmp->modify->fix[f]->style, "heat/gran", 9) != 0 || window < 1) return -1;
    rec->conduction = static_cast<FixHeatGranCond *>(rec->lmp->modify->fix[f]);
    rec->window = window;
    return 0;
}

// The walls heat/gran conducts through whose collisions the host gives heat, of the primitive
// walls (`meshes` 0) or the mesh walls (1) as last given: 4 numbers per wall, in their order:
// temperature [K] (< 0: none), atom type, contact area mode (0 overlap, 1 constant, 2
// projection), constant area [m^2]. Their new contacts keep flux histories as pairs do. -1 if
// n is not the number of such walls or a type is out of range.
int collheat_events_wall_conduction(void *handle, int meshes, int n, const double *params)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    if (size_t(n) != (meshes ? rec->meshes.size() : rec->prims.size())) return -1;
    std::vector<WallHeat> heat;
    for (int w = 0; w < n; ++w) {
        const double *p = params + 4 * w;
        const int type = int(p[1]);
        if (p[0] >= 0 && (type < 1 || type > rec->lmp->atom->ntypes)) return -1;
        heat.push_back(WallHeat{p[0], type, int(p[2]), p[3]});
    }
    (meshes ? rec->mesh_heat : rec->prim_heat) = heat;
    return 0;
}

// What heat/gran added to this rank's atoms' m c Temp since the last call [J]: out[0] from its
// sources, out[1] from its conduction (0 without heat/gran).
void collheat_events_heat_gran_heat(void *handle, double *out)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    out[0] = rec->source_heat;
    out[1] = rec->flux_heat;
    rec->source_heat = rec->flux_heat = 0.0;
}

// Flux histories handed over and waiting (HEAD + window doubles each); with `all`, first hand
// over every history still filling (a stop, a checkpoint: what follows takes none back).
int collheat_events_histories(void *handle, int all)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    if (all) {
        for (size_t k = 0; k < rec->history.size(); ++k)     // (``carry`` is empty between steps)
            if (rec->history[k] >= 0) { rec->close_history(rec->history[k]); rec->history[k] = -1; }
    }
    return rec->window ? int(rec->done.size() / (HEAD + rec->window)) : 0;
}

// Copy the waiting histories into out (n of them, HEAD + window doubles each) and drop them.
int collheat_events_take_histories(void *handle, double *out, int n)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    const size_t row = HEAD + rec->window;
    n = std::min<int>(n, rec->window ? int(rec->done.size() / row) : 0);
    std::memcpy(out, rec->done.data(), sizeof(double) * row * n);
    rec->done.erase(rec->done.begin(), rec->done.begin() + row * n);
    return n;
}

// Atoms that appeared since the last call (with heat/gran): their number; with out, copy their
// id, Temp at their first step and that step (3 doubles each, up to n) and forget them.
int collheat_events_appeared(void *handle, double *out, int n)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    const int have = int(rec->appeared.size() / 3);
    if (!out) return have;
    n = std::min(n, have);
    std::memcpy(out, rec->appeared.data(), sizeof(double) * 3 * n);
    rec->appeared.erase(rec->appeared.begin(), rec->appeared.begin() + 3 * n);
    return n;
}

// Separation speeds to impose at the end of n open contacts: their keys, the speed [m/s] and,
// for a wall, the normal from the wall to the particle.
void collheat_events_restitution(void *handle, int n, const int64_t *keys, const double *speed, const double *normal)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    for (int k = 0; k < n; ++k) {
        Recorder::Target t;
        t.speed = speed[k];
        for (int c = 0; c < 3; ++c) t.n[c] = normal[3 * k + c];
        rec->targets[uint64_t(keys[k])] = t;
    }
}

// Forget the separation speeds of n contacts (keys) the host saw end: under MPI every rank
// keeps every speed given (a contact may move to another rank), and only the rank where the
// contact ended used its own.
void collheat_events_forget(void *handle, int n, const int64_t *keys)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    for (int k = 0; k < n; ++k) rec->targets.erase(uint64_t(keys[k]));
}

// How many mesh walls the last call read from LIGGGHTS' mesh contact history (the others by geometry).
int collheat_events_meshes_by_history(void *handle) { return static_cast<Recorder *>(handle)->meshes_by_history; }

// Events waiting, open contacts now, and all BEGIN and END events recorded so far.
int collheat_events_waiting(void *handle) { return int(static_cast<Recorder *>(handle)->rows.size() / ROW); }
int collheat_events_open(void *handle) { return int(static_cast<Recorder *>(handle)->open_count()); }
long long collheat_events_total(void *handle, int ended)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    return ended ? rec->ended : rec->begun;
}

// Copy up to max_rows waiting events (ROW doubles each, oldest first) into out and drop them;
// returns the number copied.
int collheat_events_take(void *handle, double *out, int max_rows)
{
    Recorder *rec = static_cast<Recorder *>(handle);
    const int n = std::min<int>(max_rows, int(rec->rows.size() / ROW));
    std::memcpy(out, rec->rows.data(), sizeof(double) * ROW * n);
    rec->rows.erase(rec->rows.begin(), rec->rows.begin() + ROW * n);
    return n;
}

// Detach: the fix keeps a callback that does nothing harmful only while the Recorder lives,
// so this is for the end of the LIGGGHTS instance.
void collheat_events_free(void *handle) { delete static_cast<Recorder *>(handle); }

}

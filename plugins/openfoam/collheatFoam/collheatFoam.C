/*---------------------------------------------------------------------------*\
Application
    collheatFoam

Description
    Volume-averaged incompressible gas phase of a CFD-DEM simulation (OpenFOAM v1912),
    after DPMFoam's equations, in the "model A" form (pressure and gravity shared by the
    fluid fraction):

        d(alpha)/dt + div(alpha U) = 0
        d(alpha U)/dt + div(alpha U U) - div(alpha nu_eff grad U)
            = -alpha grad(p) + alpha g + (Ksl/rho) (Us - U) + fvOptions

    p is the kinematic pressure (Pa per rho), alpha the fluid volume fraction, Ksl the
    particle-fluid momentum exchange coefficient per cell (kg/m^3/s, implicit in U), Us the
    exchange-weighted particle velocity per cell (m/s). fp = Ksl (Us - U) is the interphase
    force per unit volume that the particles exert on the fluid (N/m^3; f_p in Kosinski et
    al. 2014), written with the other fields. PIMPLE/PISO set by system/fvSolution.

    Discretisation: face momentum (as twoPhaseEulerFoam's faceMomentum option). Time
    derivative, exchange, gravity and pressure act on the cell faces, with the face
    exchange coefficient alpha_f^2 interp(Ksl/(rho alpha^2)), i.e. the interpolated
    resistance, and the cell velocity is the reconstructed superficial flux over alpha. A
    cell-centred exchange lost the pressure drop of about one cell at each edge of a packed
    bed (a 4-cell bed: 22 % below Ergun); this form gets a steady bed's drop right when
    its edges lie on faces (tests/engines/test_fluid.py, cases/packed-bed-ergun).

    With -energy it also solves the gas temperature T (TEqn.H) with the particles' heat
    Qgas as a source; Cp (J/(kg K)) and kappa (W/(m K)) of the gas come from
    transportProperties, the boundary conditions from 0/T.

    Without -link it runs as a plain solver with alpha, Ksl, Us read from the start time
    (defaults 1, 0, 0). With -link DIR it serves a Python host (pyhost/openfoam.py) through
    two named pipes per rank, DIR/rank<N>.in and DIR/rank<N>.out; see hostLink.H.
\*---------------------------------------------------------------------------*/

#include "fvCFD.H"
#include "singlePhaseTransportModel.H"
#include "PhaseIncompressibleTurbulenceModel.H"
#include "pimpleControl.H"
#include "fvOptions.H"
#include "interpolation.H"
#include "fixedFluxPressureFvPatchScalarField.H"
#include <cstdio>

int main(int argc, char *argv[])
{
    argList::addNote
    (
        "Volume-averaged incompressible fluid of a CFD-DEM simulation,"
        " coupled to a Python host through named pipes (-link)."
    );
    argList::addOption("link", "dir", "serve the Python host through pipes in dir");
    argList::addBoolOption("energy", "solve the gas temperature T (Cp, kappa in transportProperties)");
    argList::addBoolOption("restart", "continue from a start time the host wrote (its alpha is the old one)");
    argList::addBoolOption("noDdtAlpha", "leave d(alpha)/dt out of the continuity equation (CFDEM's default, "
                           "useDDTvoidfraction off)");

    #include "setRootCaseLists.H"
    #include "createTime.H"
    #include "createMesh.H"
    #include "createControl.H"
    #include "createFields.H"
    #include "createFvOptions.H"

    if (args.found("link"))
    {
        #include "hostLink.H"
    }
    else
    {
        Info<< "\nStarting time loop\n" << endl;
        while (runTime.run())
        {
            ++runTime;
            #include "fluidStep.H"
        }
    }

    Info<< "End\n" << endl;
    return 0;
}

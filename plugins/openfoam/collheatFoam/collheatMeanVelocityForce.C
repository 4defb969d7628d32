#include "collheatMeanVelocityForce.H"
#include "addToRunTimeSelectionTable.H"
#include "fvc.H"

namespace Foam
{
namespace fv
{
    defineTypeNameAndDebug(collheatMeanVelocityForce, 0);
    addToRunTimeSelectionTable(option, collheatMeanVelocityForce, dictionary);
}
}


Foam::fv::collheatMeanVelocityForce::collheatMeanVelocityForce
(
    const word& sourceName,
    const word& modelType,
    const dictionary& dict,
    const fvMesh& mesh
)
:
    meanVelocityForce(sourceName, modelType, dict, mesh),
    superficial_(coeffs_.lookupOrDefault<bool>("superficial", false))
{}


const Foam::volScalarField& Foam::fv::collheatMeanVelocityForce::alpha() const
{
    return mesh_.lookupObject<volScalarField>("alpha");
}


Foam::scalar Foam::fv::collheatMeanVelocityForce::magUbarAve
(
    const volVectorField& U
) const
{
    const volScalarField& a = alpha();
    const scalarField& cv = mesh_.V();
    scalar sum = 0.0;
    forAll(cells_, i)
    {
        const label celli = cells_[i];
        sum += (flowDir_ & U[celli])*cv[celli]*(superficial_ ? a[celli] : 1.0);
    }
    reduce(sum, sumOp<scalar>());
    return sum/V_;
}


void Foam::fv::collheatMeanVelocityForce::correct(volVectorField& U)
{
    const volScalarField& a = alpha();
    const surfaceScalarField& rAUf = mesh_.lookupObject<surfaceScalarField>("rAUf");
    const volScalarField rA(fvc::average(rAUf));
    const scalarField& cv = mesh_.V();
    scalar response = 0.0;
    forAll(cells_, i)
    {
        const label celli = cells_[i];
        response += a[celli]*(superficial_ ? a[celli] : 1.0)*rA[celli]*cv[celli];
    }
    reduce(response, sumOp<scalar>());
    response /= V_;

    const scalar magUbarAve = this->magUbarAve(U);
    dGradP_ = relaxation_*(mag(Ubar_) - magUbarAve)/response;

    // The step's flow corrected by what dG would have done in it, through the flux (the
    // next step starts from phi, not U): the flux over internal and coupled faces (not walls
    // or inlets), the superficial flux, and U.
    surfaceScalarField& phi = mesh_.lookupObjectRef<surfaceScalarField>("phi");
    const surfaceScalarField& alphaf = mesh_.lookupObject<surfaceScalarField>("alphaf");
    const surfaceScalarField dPhi(rAUf*alphaf*dGradP_*(flowDir_ & mesh_.Sf()));
    phi.primitiveFieldRef() += dPhi.primitiveField();
    forAll(phi.boundaryField(), patchi)
    {
        if (phi.boundaryField()[patchi].coupled())
        {
            phi.boundaryFieldRef()[patchi] += dPhi.boundaryField()[patchi];
        }
    }
    mesh_.lookupObjectRef<surfaceScalarField>("alphaPhi") = alphaf*phi;
    forAll(cells_, i)
    {
        const label celli = cells_[i];
        U[celli] += a[celli]*rA[celli]*dGradP_*flowDir_;
    }
    U.correctBoundaryConditions();

    const scalar gradP = gradP0_ + dGradP_;
    Info<< "Pressure gradient source: " << (superficial_ ? "superficial " : "")
        << "Ubar = " << magUbarAve << ", pressure gradient = " << gradP << endl;
    writeProps(gradP);
}


void Foam::fv::collheatMeanVelocityForce::addSup
(
    fvMatrix<vector>& eqn,
    const label fieldi
)
{
    volVectorField::Internal Su
    (
        IOobject
        (
            name_ + fieldNames_[fieldi] + "Sup",
            mesh_.time().timeName(),
            mesh_,
            IOobject::NO_READ,
            IOobject::NO_WRITE
        ),
        mesh_,
        dimensionedVector(eqn.dimensions()/dimVolume, Zero)
    );
    const volScalarField& a = alpha();
    const scalar gradP = gradP0_ + dGradP_;
    forAll(cells_, i)
    {
        const label celli = cells_[i];
        Su[celli] = a[celli]*flowDir_*gradP;
    }
    eqn += Su;
}


void Foam::fv::collheatMeanVelocityForce::constrain
(
    fvMatrix<vector>&,
    const label
)
{
    gradP0_ += dGradP_;
    dGradP_ = 0.0;
}

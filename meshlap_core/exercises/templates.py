"""The student file ``meshlap exercises init`` writes: one stub per task with its signature,
shapes, conventions, the formula to implement and its reference, and no solution."""

from __future__ import annotations

from ..options import EXERCISE_TASKS

HEADER = '''"""meshlap exercises: implement each function, then run

    meshlap check {filename}

(or ``meshlap check {filename} --task cotan_laplacian`` for one task).

Conventions (the same as the lab's):
- V is an (n,3) float array of positions, F an (m,3) int array of counter-clockwise triangles.
- n = len(V) always: a vertex in no face still has its row (of zeros) and its entry.
- Every Laplacian is NEGATIVE semidefinite: Δx = −2 H n, with H > 0 on a sphere (outward normals).
- Matrices may be scipy.sparse or dense numpy arrays of shape (n, n).
- Use numpy and scipy freely (libigl too); importing meshlap is refused by the checker (it
  would be the answer).
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
'''

STUBS: dict[str, str] = {
    "uniform_laplacian": '''
def uniform_laplacian(V, F):
    """Uniform (graph) Laplacian L = D⁻¹A − I.

    (L f)_i = (1/|N(i)|) Σ_{j∈N(i)} (f_j − f_i): A is the 0/1 adjacency (edges of F), D the
    degrees. Rows sum to 0; the row of a vertex in no face is zero.

    Returns L : (n,n).
    """
    raise NotImplementedError
''',
    "cotan_laplacian": '''
def cotan_laplacian(V, F):
    """Cotangent stiffness C (Pinkall & Polthier 1993), negative semidefinite.

    C_ij = ½ (cot α_ij + cot β_ij) for an edge ij (α, β the angles opposite it; a boundary edge
    has one), C_ii = −Σ_j C_ij. A weight may be negative (non-Delaunay edge): keep it.

    Returns C : (n,n), symmetric, rows summing to 0.
    """
    raise NotImplementedError
''',
    "barycentric_areas": '''
def barycentric_areas(V, F):
    """Barycentric vertex areas: A_i = ⅓ Σ of the areas of the faces around i.

    Returns A : (n,), summing to the surface area; 0 for a vertex in no face.
    """
    raise NotImplementedError
''',
    "voronoi_areas": '''
def voronoi_areas(V, F):
    """Mixed Voronoi areas (Meyer, Desbrun, Schröder & Barr 2003, "Discrete
    differential-geometry operators", Fig. 4).

    Non-obtuse triangle: corner i gets ⅛ (|e_ij|² cot θ_k + |e_ik|² cot θ_j). Obtuse triangle:
    the obtuse corner gets ½ of the triangle's area, the two others ¼ each.

    Returns A : (n,), summing to the surface area.
    """
    raise NotImplementedError
''',
    "mass_matrix": '''
def mass_matrix(V, F):
    """Lumped mass matrix M = diag(mixed Voronoi areas) (see voronoi_areas).

    Returns M : (n,n) diagonal.
    """
    raise NotImplementedError
''',
    "mean_curvature_normal": '''
def mean_curvature_normal(V, F):
    """Mean curvature normal H n = −½ Δx with Δ = M⁻¹ C (C: cotan_laplacian, M: mass_matrix,
    mixed Voronoi). A vertex with zero area gets 0.

    Returns Hn : (n,3), pointing outwards on a sphere (units 1/length).
    """
    raise NotImplementedError
''',
    "mean_curvature": '''
def mean_curvature(V, F):
    """Signed mean curvature H = −½ (Δx · n), Δ = M⁻¹C (mixed Voronoi M), n the unit
    angle-weighted vertex normal n_i ∝ Σ_f θ_i,f n_f (Thürmer & Wüthrich 1998).

    Returns H : (n,), ≈ 1/r on a sphere of radius r.
    """
    raise NotImplementedError
''',
    "angle_defect": '''
def angle_defect(V, F, boundary):
    """Angle defect (integrated Gaussian curvature) at every vertex.

    Interior vertex: 2π − Σθ (θ the corner angles at the vertex, radians). Boundary vertex,
    by rule: "pi": π − Σθ (Gauss–Bonnet with its boundary term), "2pi": 2π − Σθ, "zero": 0.
    A vertex in no face: 0.

    Returns d : (n,). Σ d = 2πχ on a closed surface.
    """
    raise NotImplementedError
''',
    "one_ring": '''
def one_ring(F, n):
    """Ordered one-ring of every vertex.

    ring[i] lists the neighbours of i counter-clockwise: for consecutive a, b, (i, a, b) is a
    face (in some rotation). Interior vertex: any starting neighbour. Boundary vertex: start at
    the boundary neighbour from which the fan proceeds counter-clockwise.

    Returns a list of n integer arrays (empty for a vertex in no face).
    """
    raise NotImplementedError
''',
    "eigenbasis": '''
def eigenbasis(V, F, k):
    """The k lowest eigenpairs of the generalized problem K u = λ M u, K = −C (cotan_laplacian),
    M = mass_matrix (mixed Voronoi). Ascending λ ≥ 0; eigenvectors M-orthonormal: UᵀMU = I.

    Returns (lam, U) : (k,) and (n,k).
    """
    raise NotImplementedError
''',
    "spectral_reconstruction": '''
def spectral_reconstruction(X, U, M):
    """Project X on the span of the M-orthonormal basis U: X̂ = U (Uᵀ M X).

    X : (n,3), U : (n,k) with UᵀMU = I, M : (n,n) diagonal mass matrix.
    Returns X̂ : (n,3).
    """
    raise NotImplementedError
''',
    "explicit_step": '''
def explicit_step(V, F, lam):
    """One explicit (forward Euler) smoothing step with the uniform Laplacian:
    V′ = V + λ L V (L from uniform_laplacian).

    Returns V′ : (n,3).
    """
    raise NotImplementedError
''',
    "implicit_step": '''
def implicit_step(V, F, lam):
    """One implicit (backward Euler) step with the cotangent Laplacian (Desbrun et al. 1999):
    solve (M − λ C) V′ = M V, C = cotan_laplacian, M = mass_matrix (mixed Voronoi).

    Returns V′ : (n,3).
    """
    raise NotImplementedError
''',
    "taubin_step": '''
def taubin_step(V, F, lam, mu):
    """One Taubin step (Taubin 1995) with the uniform Laplacian L: V₁ = V + λ L V, then
    V′ = V₁ + μ L V₁ (μ < 0 is given).

    Returns V′ : (n,3).
    """
    raise NotImplementedError
''',
    "heat_geodesic": '''
def heat_geodesic(V, F, source, m):
    """Geodesic distance from vertex ``source`` by the heat method (Crane, Weischedel &
    Wardetzky, "Geodesics in heat", ACM TOG 2013), on a closed connected mesh.

    K = −C (cotan_laplacian), M = mass_matrix (mixed Voronoi), h the mean edge length (each
    edge once), t = m·h² (the time must scale with the mesh):
    1. heat: solve (M + t K) u = δ, δ one at the source and zero elsewhere;
    2. per face: X = −∇u / |∇u| (∇ the gradient of the piecewise-linear u; X = 0 where ∇u = 0);
    3. Poisson: K φ = Gᵀ A X (G the (3m, n) face gradient, A the diagonal of face areas:
       Gᵀ A X is minus the integrated divergence of X); K is singular (constants): pin one
       vertex, e.g. φ_0 = 0, and solve for the others;
    4. d = φ − φ[source].

    Returns d : (n,), 0 at the source and increasing away from it (units of length).
    """
    raise NotImplementedError
''',
}


def template(filename: str = "exercises.py", tasks: tuple[str, ...] = EXERCISE_TASKS) -> str:
    """The student file's text with a stub for each task in ``tasks``."""
    return HEADER.format(filename=filename) + "".join("\n" + STUBS[t] for t in tasks)

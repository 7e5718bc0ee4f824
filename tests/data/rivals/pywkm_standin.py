"""Stand-in for the private PyWKM package (NOT the real one): wkm(A) = cosh(sqrt(A)) [, sinhc(sqrt(A))]
for symmetric A <= 0, by eigendecomposition. Only needed so that gautschiIntegrators.matrix_functions imports;
the reference runs use the package's own SymDiagonalizationEvaluator, which does not call wkm."""
import numpy as np
def wkm(A, return_sinhc=False):
    w, V = np.linalg.eigh(-np.asarray(A, float)); r = np.sqrt(np.maximum(w, 0))
    C = V @ np.diag(np.cos(r)) @ V.T
    if not return_sinhc: return C
    return C, V @ np.diag(np.sinc(r / np.pi)) @ V.T

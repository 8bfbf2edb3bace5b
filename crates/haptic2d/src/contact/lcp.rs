//! Small dense LCP solvers (§7.3): exact enumeration for n ≤ 6, projected Gauss–Seidel beyond.

"""The numerical core: the loop-closure rows in every execution strategy (Pinocchio, numba, numpy stacks,
polynomials) behind one typed contract (contract.ClosureKernel), the one Newton loop that takes it, and the one
dimensionless scaling."""

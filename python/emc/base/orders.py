"""The engine orders every analysis reports, the ones plots single out, and the highest order
a sweep's spectra resolve."""

# Orders 0.5 … 6.0: the inline-3's firing order (1.5) and its multiples, the half orders of a
# four-stroke cycle, the mass forces' first and second orders.
ORDERS = tuple(k / 2 for k in range(1, 13))
# What plots of order cuts draw by default.
MAIN_ORDERS = (1.0, 1.5, 2.0, 3.0, 4.5)
# A sweep's spectra reach half an order above the highest reported one; a sampling that cannot
# resolve it aliases.
HIGHEST_ORDER = 6.5

"""Numbers published in Degée & Denoël, "An investigation on the sliding of pallets on storage
racks subjected to earthquake" (Université de Liège), quoted beside seisrack's in the paper report.

Units as printed in the paper unless stated. Table 2's "Sliding" column (7.32 … 44.34) is in
millimetres: the text says the local sliding stays "less than 5 cm" even at μ = 0.30, so 44.34
can only be mm. Its forces are exactly μ·M·g with M = 4 × 400 kg and g = 10 m/s².
"""

from __future__ import annotations

PAPER = (
    "H. Degée, V. Denoël, \"An investigation on the sliding of pallets on storage racks "
    "subjected to earthquake\", Université de Liège (Seisracks, RFCS-PR-03114)"
)

#: §II: mu/alpha below which the §II block slides continuously (text after Fig. 6)
THRESHOLD = 0.537
#: §II: the ratios of Figs 5a/5b and Fig. 7 (cases A, B, C)
FIG5_RATIOS = (0.6, 0.4)
FIG7_RATIOS = (0.75, 0.5, 0.25)

#: §IV modal result: first period [s] and its share of the horizontal mass [-]
T1_S = 0.65
PARTICIPATION = 0.996

#: §IV rack: total pallet mass [kg] (four 400 kg masses) and the g implied by Table 2 [m/s²]
PALLET_MASS_KG = 1600.0
TABLE2_G = 10.0
#: §IV friction coefficients studied
MU_VALUES = (0.80, 0.75, 0.60, 0.30)

#: Table 2 "Extreme values from Fig. 16": mu -> (disp [m], acc [m/s²], force [N], sliding [mm])
TABLE2: dict[float, tuple[float, float, float, float]] = {
    0.80: (0.087, 9.03, 12788.0, 0.00),
    0.75: (0.083, 8.74, 12000.0, 7.32),
    0.60: (0.067, 31.82, 9600.0, 6.85),
    0.30: (0.035, 69.53, 4800.0, 44.34),
}
TABLE2_COLUMNS = ("Disp. [m]", "Acc. [m/s²]", "Force [N]", "Sliding [mm]")

#: §IV observations
STOREY_HEIGHT_M = 2.0
DRIFT_RATIO = 1.0 / 23.0  # "delta_h / H = 1/23"
FORCE_RATIO_AT_0_6 = 0.75  # "with mu = 0.6 the force is already reduced to 75 %"
MAX_SLIDING_M = 0.05  # "the maximum local displacement is less than 5 cm"
ALPHA_OBSERVED = 0.9  # "alpha = 9.03/g ≈ 0.9"
NO_SLIDING_ABOVE = 0.75  # "no sliding is observed above 0.75"

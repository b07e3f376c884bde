"""The numbers of Hinzen (2009), "Simulation of Toppling Columns in
Archaeoseismology", BSSA 99(5), 2855-2875, with where each comes from.

Defaults of the parameter dataclasses (``pipeline.scenario.parameters``) and
the campaign definitions read them from here; nothing else repeats them.
"""

# Column model ("Model Setup"): a 3.5 m column, h/d ~ 6, of marble
COLUMN_HEIGHT_M = 3.5          # "height of 3.5 m"
COLUMN_HD = 6.0                # slenderness h/d of the standard column (d = 0.58 m)
MARBLE_DENSITY_KG_M3 = 2960.0  # marble test block: 4267 g for 8 x 4.5 x 40 cm -> 2.96 Mg/m^3
N_DRUMS = 7                    # the multi-drum column has seven drums
TWIN_OFFSET_M = 1.5            # columns at x = -1.5 m (drums) and +1.5 m (monolith)

# Contacts ("Model Setup", columns): normal stiffness, damping ratio, friction
COLUMN_KN_N_M = 1.2e8          # kn of the column model; here per rim contact point
DAMPING_RATIO = 0.36           # contact damping ratio
MU_STATIC = 0.7                # static friction coefficient
MU_KINETIC = 0.6               # kinetic friction coefficient
# The friction sweep (Fig. 10): "mu_k was always set to 84% of mu_s" (the paper's own
# rule for that sweep, not the model's contact rule)
FRICTION_SWEEP_MU_K_OVER_MU_S = 0.84

# Pedestal: 5 x 5 x 1 m, 74 t, moved with the ground
PEDESTAL_SIZE_M = 5.0
PEDESTAL_THICKNESS_M = 1.0
PEDESTAL_MASS_KG = 74000.0

# Verification ("Testing the Model"): marble block and the one-sine pulse block
MARBLE_BLOCK_M = {"height": 0.40, "width": 0.08, "depth": 0.045}   # 4267 g, h/b = 5
MARBLE_BLOCK_KN_N_M = 1.2e7    # kn of the test block
PULSE_BLOCK_M = {"height": 3.113, "width": 0.795, "depth": 0.5}    # alpha 0.25, p 2.14 1/s

# Experiments (Figs 9-10 and Table 1)
SLENDERNESS_HD = tuple(round(3.0 + 0.5 * i, 1) for i in range(13))   # h/d 3.0 .. 9.0
FRICTION_MU_S = tuple(round(0.1 * i, 1) for i in range(1, 10))        # mu_s 0.1 .. 0.9
SWEEP_RECORD = "GM20"          # Kocaeli 1999, Izmit (paper's GM20)
RECORDS_TOPPLED_DRUMS = (13, 29)      # 13 of 29 records toppled the drum column
RECORDS_TOPPLED_MONOLITH = (7, 29)    # 7 of 29 toppled the monolith too
SELECTION_MAX_DISTANCE_KM = 40.0      # record selection: epicentral distance < 40 km
SELECTION_MIN_PGA_M_S2 = 2.0          # and horizontal PGA > 2 m/s^2
# The question: can fallen columns bound the back azimuth of the source within +-30 deg?
BACK_AZIMUTH_BOUND_DEG = 30.0

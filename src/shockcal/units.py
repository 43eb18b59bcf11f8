"""Unit factors between the hydrocode's units (cm, us, g/cc, Mbar; 1 Mbar = 1 g/cc (cm/us)^2, so
specific energy is in (cm/us)^2) and the units of the config and the tables (mm, um, ns, m/s, GPa,
J/kg/K, 1/s). Each name says its direction: a value in X times X_TO_Y is the value in Y."""

MM_TO_CM = 0.1
UM_TO_CM = 1.0e-4
NS_TO_US = 1.0e-3
J_PER_KG_TO_CODE = 1.0e-8          # 1 J/kg in (cm/us)^2
PER_S_TO_PER_US = 1.0e-6
CM_US_TO_M_S = 1.0e4
MBAR_TO_GPA = 100.0
MBAR_TO_MPA = 1.0e5

# a velocity input's unit (config `inputs.<name>.unit`) -> the factor to m/s
VELOCITY_TO_M_S = {"cm/us": CM_US_TO_M_S, "m/s": 1.0, "km/s": 1.0e3, "mm/us": 1.0e3}

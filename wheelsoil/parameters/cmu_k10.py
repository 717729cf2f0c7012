"""The CMU 3D-terramechanics rig's wheel: the K10-mini wheel of the measured single-wheel dataset
(``../shared/data/measured/cmu_3d_terramechanics``; robomechanics/3d-terramechanics parameter files, Pavlov, CMU,
MIT licence; see the dataset's README).
"""

CITATION = "CMU 3D-terramechanics single-wheel trials (Pavlov), K10-mini wheel"

#: Wheel radius and width [m].
RADIUS, WIDTH = 0.058, 0.05
#: Grouser height [m] of the two wheels tested: with grousers and smooth.
GROUSER_HEIGHT = {"grouser": 0.005, "smooth": 0.0}

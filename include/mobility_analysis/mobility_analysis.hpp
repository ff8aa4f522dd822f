#pragma once

/// Umbrella header of the ROS-free core.
#include "mobility_analysis/Assembly.hpp"
#include "mobility_analysis/ConstraintJacobian.hpp"
#include "mobility_analysis/Diagnostic.hpp"
#include "mobility_analysis/EliminationOrder.hpp"
#include "mobility_analysis/JointTypes.hpp"
#include "mobility_analysis/Kinematics.hpp"
#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/MobilityAnalysis.hpp"
#include "mobility_analysis/MobilityReport.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"
#include "mobility_analysis/RedundancyAnalysis.hpp"
#include "mobility_analysis/RedundantLinks.hpp"
#include "mobility_analysis/SelfStressBasis.hpp"
#include "mobility_analysis/SparseElimination.hpp"
#include "mobility_analysis/Tolerances.hpp"
#include "mobility_analysis/UrdfLoader.hpp"

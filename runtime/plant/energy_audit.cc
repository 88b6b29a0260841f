#include "runtime/plant/energy_audit.h"

namespace autoshovel::plant {

const char* EnergyTermName(EnergyTerm term) {
  switch (term) {
    case EnergyTerm::kTravelDriveLoss:
      return "drive motor and drivetrain loss";
    case EnergyTerm::kTravelNotRecovered:
      return "motor braking, not recovered";
    case EnergyTerm::kBrake:
      return "service brake";
    case EnergyTerm::kTyreSlip:
      return "tyre slip";
    case EnergyTerm::kRolling:
      return "rolling resistance";
    case EnergyTerm::kSoilByDrive:
      return "soil, pushed by the drive";
    case EnergyTerm::kMachineKinetic:
      return "machine kinetic energy";
    case EnergyTerm::kPumpLoss:
      return "pump and pump motor loss";
    case EnergyTerm::kCompensator:
      return "compensator throttling";
    case EnergyTerm::kMeterIn:
      return "meter-in throttling (LS margin)";
    case EnergyTerm::kBackflow:
      return "backflow";
    case EnergyTerm::kMeterOut:
      return "meter-out throttling";
    case EnergyTerm::kRelief:
      return "relief valves";
    case EnergyTerm::kCompression:
      return "oil compression";
    case EnergyTerm::kArmKinetic:
      return "arm kinetic energy";
    case EnergyTerm::kLifting:
      return "lifting (potential energy)";
    case EnergyTerm::kArmFriction:
      return "arm friction";
    case EnergyTerm::kSoilByArm:
      return "soil, cut and lifted by the arm";
    case EnergyTerm::kEndStops:
      return "cylinder end stops";
    case EnergyTerm::kCount:
      break;
  }
  return "?";
}

bool IsTravelTerm(EnergyTerm term) {
  return static_cast<int>(term) <= static_cast<int>(EnergyTerm::kMachineKinetic);
}

bool IsCylinderWorkTerm(EnergyTerm term) {
  return static_cast<int>(term) >= static_cast<int>(EnergyTerm::kArmKinetic) &&
         term != EnergyTerm::kCount;
}

double EnergyAudit::travel() const {
  double sum = 0;
  for (int k = 0; k < kEnergyTermCount; ++k) {
    if (IsTravelTerm(static_cast<EnergyTerm>(k))) sum += terms[k];
  }
  return sum;
}

double EnergyAudit::hydraulic() const {
  double sum = 0;
  for (int k = 0; k < kEnergyTermCount; ++k) {
    if (!IsTravelTerm(static_cast<EnergyTerm>(k))) sum += terms[k];
  }
  return sum;
}

double EnergyAudit::cylinder_work() const {
  double sum = 0;
  for (int k = 0; k < kEnergyTermCount; ++k) {
    if (IsCylinderWorkTerm(static_cast<EnergyTerm>(k))) sum += terms[k];
  }
  return sum;
}

double EnergyAudit::soil() const {
  return (*this)[EnergyTerm::kSoilByDrive] + (*this)[EnergyTerm::kSoilByArm];
}

EnergyAudit& EnergyAudit::operator+=(const EnergyAudit& o) {
  for (int k = 0; k < kEnergyTermCount; ++k) terms[k] += o.terms[k];
  return *this;
}

EnergyAudit EnergyAudit::operator-(const EnergyAudit& o) const {
  EnergyAudit d = *this;
  for (int k = 0; k < kEnergyTermCount; ++k) d.terms[k] -= o.terms[k];
  return d;
}

}  // namespace autoshovel::plant

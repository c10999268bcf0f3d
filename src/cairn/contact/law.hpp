// Contact laws of multimaterial MPM (seed 004 Sec. 2.2, Eq. 7-10; docs/contact.md).
//
// At a contact node, fields alpha and beta with masses m_a, m_b and momenta p_a, p_b would move
// together with the centre-of-mass velocity after the change
//     dp0 = m_a (v_cm - v_a) = m_red (v_b - v_a),   m_red = m_a m_b / (m_a + m_b)   (Eq. 8).
// A law returns the momentum change dp of alpha (beta gets -dp) for an interface that is in
// contact. Writing dp0 = (dp0.n) n + |dp0_t| t (t chosen so that dp0.t > 0, as the corrected
// text of Sec. 2.2 says), a law that lets the interface slide with tangential traction S_slide
// over the contact area A_c returns
//     dp = (dp0.n) n + min(S_slide A_c dt, |dp0_t|) t                             (Eq. 8-10),
// with the normal compression N_c = -dp0.n / (A_c dt) (positive when the fields approach).
// Each law is one file in contact/laws/ with one CAIRN_REGISTER_CONTACT_LAW line.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cairn/bc/expression.hpp"
#include "cairn/config/config.hpp"
#include "cairn/math/types.hpp"
#include "cairn/util/registry.hpp"

namespace cairn {

/// What a law sees for one field pair at one contact node (3 components; unused ones zero).
struct ContactInput {
  Vec3 dp0 = Vec3::Zero();     ///< the stick change of alpha, m_red (v_b - v_a)
  Vec3 normal = Vec3::Zero();  ///< unit normal from alpha to beta
  double reduced_mass = 0.0;   ///< m_red
  double area = 0.0;           ///< contact area A_c of the node (docs/contact.md)
  double dt = 0.0;
  double time = 0.0;
};

class ContactLaw {
 public:
  virtual ~ContactLaw() = default;
  /// A bonded (perfect) interface: corrected at every node that sees both fields, without
  /// detection, in tension as in compression.
  [[nodiscard]] virtual bool bonded() const { return false; }
  /// Momentum change of alpha for an interface in contact (approaching and touching).
  [[nodiscard]] virtual Vec3 momentum_change(const ContactInput& in) const = 0;
};

/// dp of a sliding interface with tangential traction `traction` (Eq. 8-10): the normal part of
/// dp0 and at most the stick value of the tangential part.
inline Vec3 sliding_change(const ContactInput& in, double traction) {
  const double dn = in.dp0.dot(in.normal);
  const Vec3 tangential = in.dp0 - dn * in.normal;
  const double dt_stick = tangential.norm();
  const double allowed = traction * in.area * in.dt;
  if (!(dt_stick > allowed)) return in.dp0;  // the traction needed to stick is available
  return dn * in.normal + (allowed / dt_stick) * tangential;
}

using ContactLawRegistry = Registry<ContactLaw, const ContactLawConfig&, const Constants&>;

/// Build the law named by `config.law`; throws UnknownName or std::invalid_argument.
std::unique_ptr<ContactLaw> make_contact_law(const ContactLawConfig& config, const Constants& constants);

}  // namespace cairn

#define CAIRN_CONTACT_LAW_CONCAT2(a, b) a##b
#define CAIRN_CONTACT_LAW_CONCAT(a, b) CAIRN_CONTACT_LAW_CONCAT2(a, b)
/// Register class Type (constructible from (const ContactLawConfig&, const Constants&)) as `name`.
#define CAIRN_REGISTER_CONTACT_LAW(Type, name, doc)                                                     \
  [[maybe_unused]] static const bool CAIRN_CONTACT_LAW_CONCAT(cairn_contact_law_registered_, __LINE__) = \
      ::cairn::ContactLawRegistry::instance().add(                                                      \
          name, doc, [](const ::cairn::ContactLawConfig& c, const ::cairn::Constants& k) {              \
            return std::unique_ptr<::cairn::ContactLaw>(new Type(c, k));                                \
          })

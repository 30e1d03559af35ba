#include "silentmpm/particles.hpp"

namespace smpm {

namespace {
template <class T>
void apply(std::vector<T>& v, const std::vector<uint32_t>& perm) {
  std::vector<T> out(perm.size());
  for (std::size_t k = 0; k < perm.size(); ++k) out[k] = v[perm[k]];
  v.swap(out);
}
}  // namespace

void Particles::resize(std::size_t n) {
  for (auto* v : {&x, &y, &x0, &y0, &vx, &vy, &mass, &vol, &sxx, &syy, &szz, &sxy, &eps_p})
    v->resize(n, 0.0);
  if (film_) {
    for (auto* v : {&dnx, &dny, &dL, &dtnf, &dttf, &jump_n, &jump_t, &ubar}) v->resize(n, 0.0);
    state.resize(n, 0);
  }
  id.resize(n, 0);
  body.resize(n, 0);
  group.resize(n, 0);
}

void Particles::enable_film() {
  film_ = true;
  const std::size_t n = size();
  for (auto* v : {&dnx, &dny, &dL, &dtnf, &dttf, &jump_n, &jump_t, &ubar}) v->resize(n, 0.0);
  state.resize(n, 0);
}

void Particles::permute(const std::vector<uint32_t>& perm) {
  for (auto* v : {&x, &y, &x0, &y0, &vx, &vy, &mass, &vol, &sxx, &syy, &szz, &sxy, &eps_p})
    apply(*v, perm);
  if (film_) {
    for (auto* v : {&dnx, &dny, &dL, &dtnf, &dttf, &jump_n, &jump_t, &ubar}) apply(*v, perm);
    apply(state, perm);
  }
  apply(id, perm);
  apply(body, perm);
  apply(group, perm);
}

std::vector<uint32_t> Particles::sort_by_id() {
  std::vector<uint32_t> perm(size());
  for (std::size_t k = 0; k < size(); ++k) perm[id[k]] = static_cast<uint32_t>(k);
  permute(perm);
  return perm;
}

void Particles::pack(std::size_t k, std::vector<double>& out) const {
  for (auto* v : {&x, &y, &x0, &y0, &vx, &vy, &mass, &vol, &sxx, &syy, &szz, &sxy, &eps_p})
    out.push_back((*v)[k]);
  if (film_) {
    for (auto* v : {&dnx, &dny, &dL, &dtnf, &dttf, &jump_n, &jump_t, &ubar}) out.push_back((*v)[k]);
    out.push_back(state[k]);
  }
  out.push_back(id[k]);
  out.push_back(body[k]);
  out.push_back(group[k]);
}

std::size_t Particles::unpack(const double* in) {
  const std::size_t k = size();
  resize(k + 1);
  std::size_t r = 0;
  for (auto* v : {&x, &y, &x0, &y0, &vx, &vy, &mass, &vol, &sxx, &syy, &szz, &sxy, &eps_p})
    (*v)[k] = in[r++];
  if (film_) {
    for (auto* v : {&dnx, &dny, &dL, &dtnf, &dttf, &jump_n, &jump_t, &ubar}) (*v)[k] = in[r++];
    state[k] = static_cast<uint8_t>(in[r++]);
  }
  id[k] = static_cast<uint32_t>(in[r++]);
  body[k] = static_cast<uint16_t>(in[r++]);
  group[k] = static_cast<uint16_t>(in[r++]);
  return r;
}

}  // namespace smpm

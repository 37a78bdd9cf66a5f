#pragma once
// Access to the few private members of Box2D 2.4.1 that an exact snapshot must read and write
// (contact flags, the broad-phase tree, the previous step's inverse time step, body sweeps, the
// arm's joint impulses).
// Box2D 2.4 has no snapshot API; this uses the standard rule that explicit template
// instantiation may name private members. Include from exactly one translation unit
// (snapshot.cpp): each instantiation must appear once in the program.
#include <box2d/box2d.h>

namespace dicestack::detail {

template <class Tag, typename Tag::type Member>
struct Box2dMember {
  friend typename Tag::type member(Tag) { return Member; }
};

#define DICESTACK_BOX2D_MEMBER(TagName, Class, Type, Name) \
  struct TagName {                                          \
    using type = Type Class::*;                             \
    friend type member(TagName);                            \
  };                                                        \
  template struct Box2dMember<TagName, &Class::Name>

DICESTACK_BOX2D_MEMBER(WorldInvDt0, b2World, float, m_inv_dt0);
DICESTACK_BOX2D_MEMBER(WorldNewContacts, b2World, bool, m_newContacts);
DICESTACK_BOX2D_MEMBER(WorldStepComplete, b2World, bool, m_stepComplete);
DICESTACK_BOX2D_MEMBER(BroadPhaseTree, b2BroadPhase, b2DynamicTree, m_tree);
DICESTACK_BOX2D_MEMBER(BroadPhaseMoveBuffer, b2BroadPhase, int32*, m_moveBuffer);
DICESTACK_BOX2D_MEMBER(BroadPhaseMoveCapacity, b2BroadPhase, int32, m_moveCapacity);
DICESTACK_BOX2D_MEMBER(BroadPhaseMoveCount, b2BroadPhase, int32, m_moveCount);
DICESTACK_BOX2D_MEMBER(TreeRoot, b2DynamicTree, int32, m_root);
DICESTACK_BOX2D_MEMBER(TreeNodes, b2DynamicTree, b2TreeNode*, m_nodes);
DICESTACK_BOX2D_MEMBER(TreeNodeCount, b2DynamicTree, int32, m_nodeCount);
DICESTACK_BOX2D_MEMBER(TreeNodeCapacity, b2DynamicTree, int32, m_nodeCapacity);
DICESTACK_BOX2D_MEMBER(TreeFreeList, b2DynamicTree, int32, m_freeList);
DICESTACK_BOX2D_MEMBER(TreeInsertionCount, b2DynamicTree, int32, m_insertionCount);
DICESTACK_BOX2D_MEMBER(ContactFlags, b2Contact, uint32, m_flags);
DICESTACK_BOX2D_MEMBER(ContactToiCount, b2Contact, int32, m_toiCount);
DICESTACK_BOX2D_MEMBER(ContactToi, b2Contact, float, m_toi);
DICESTACK_BOX2D_MEMBER(BodyXf, b2Body, b2Transform, m_xf);
DICESTACK_BOX2D_MEMBER(BodySweep, b2Body, b2Sweep, m_sweep);
DICESTACK_BOX2D_MEMBER(BodyFlags, b2Body, uint16, m_flags);
DICESTACK_BOX2D_MEMBER(BodySleepTime, b2Body, float, m_sleepTime);
DICESTACK_BOX2D_MEMBER(FixtureProxies, b2Fixture, b2FixtureProxy*, m_proxies);
DICESTACK_BOX2D_MEMBER(JointImpulse, b2RevoluteJoint, b2Vec2, m_impulse);
DICESTACK_BOX2D_MEMBER(JointMotorImpulse, b2RevoluteJoint, float, m_motorImpulse);
DICESTACK_BOX2D_MEMBER(JointLowerImpulse, b2RevoluteJoint, float, m_lowerImpulse);
DICESTACK_BOX2D_MEMBER(JointUpperImpulse, b2RevoluteJoint, float, m_upperImpulse);

#undef DICESTACK_BOX2D_MEMBER

/// The private member of `object` named by Tag.
template <class Tag, class Object>
auto& get(Object& object) {
  return object.*member(Tag{});
}

}  // namespace dicestack::detail

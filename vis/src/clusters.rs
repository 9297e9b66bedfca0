//! PRT2 clusters: visibility is computed between clusters, then every leaf gets the leaves of
//! all clusters its own cluster sees.

use crate::VisError;
use crate::bitset::BitSet;
use crate::pvs::Pvs;
use quake_formats::prt::PortalFile;

/// The vis leaves of each cluster, and each leaf's cluster.
#[derive(Debug, Clone)]
pub struct Clusters {
    members: Vec<Vec<u32>>,
    /// `None` for a leaf no cluster lists: it has no portals, so it sees only itself.
    cluster_of: Vec<Option<u32>>,
}

impl Clusters {
    /// The clusters of a PRT2 file; `None` for a PRT1 file (every leaf its own cluster).
    pub fn from_prt(prt: &PortalFile) -> Result<Option<Clusters>, VisError> {
        let Some(members) = &prt.clusters else {
            return Ok(None);
        };
        let num_leafs = prt.num_leafs as usize;
        let mut cluster_of = vec![None; num_leafs];
        for (cluster, leafs) in members.iter().enumerate() {
            for &leaf in leafs {
                let slot = cluster_of
                    .get_mut(leaf as usize)
                    .ok_or(VisError::ClusterLeaf {
                        cluster,
                        leaf,
                        num_leafs,
                    })?;
                if let Some(first) = slot.replace(cluster as u32) {
                    return Err(VisError::LeafInTwoClusters {
                        leaf,
                        clusters: [first as usize, cluster],
                    });
                }
            }
        }
        Ok(Some(Clusters {
            members: members.clone(),
            cluster_of,
        }))
    }

    /// Leaf rows from cluster rows: a leaf sees every leaf of every cluster its cluster sees.
    pub fn expand(&self, cluster_rows: &[BitSet]) -> Pvs {
        debug_assert_eq!(cluster_rows.len(), self.members.len());
        let num_leafs = self.cluster_of.len();
        let cluster_leafs: Vec<BitSet> = cluster_rows
            .iter()
            .map(|seen| {
                let mut leafs = BitSet::new(num_leafs);
                for c in seen.iter() {
                    for &leaf in &self.members[c] {
                        leafs.insert(leaf as usize);
                    }
                }
                leafs
            })
            .collect();
        let rows = self
            .cluster_of
            .iter()
            .enumerate()
            .map(|(leaf, cluster)| match cluster {
                Some(c) => cluster_leafs[*c as usize].clone(),
                None => {
                    let mut alone = BitSet::new(num_leafs);
                    alone.insert(leaf);
                    alone
                }
            })
            .collect();
        Pvs::new(rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prt(num_leafs: u32, clusters: Vec<Vec<u32>>) -> PortalFile {
        PortalFile {
            num_leafs,
            portals: Vec::new(),
            clusters: Some(clusters),
        }
    }

    #[test]
    fn rows_expand_to_every_leaf_of_every_seen_cluster() {
        // Clusters {0, 2}, {1}, {3}; leaf 4 is in none.
        let clusters = Clusters::from_prt(&prt(5, vec![vec![0, 2], vec![1], vec![3]]))
            .expect("valid")
            .expect("clustered");
        let mut rows = vec![BitSet::new(3), BitSet::new(3), BitSet::new(3)];
        for (from, to) in [(0, 0), (0, 1), (1, 1), (1, 0), (2, 2)] {
            rows[from].insert(to);
        }
        let pvs = clusters.expand(&rows);
        let row = |leaf: usize| pvs.row(leaf).iter().collect::<Vec<_>>();
        assert_eq!(row(0), vec![0, 1, 2]);
        assert_eq!(row(2), vec![0, 1, 2]);
        assert_eq!(row(1), vec![0, 1, 2]);
        assert_eq!(row(3), vec![3]);
        assert_eq!(row(4), vec![4]);
    }

    #[test]
    fn bad_cluster_lists_are_refused() {
        assert!(
            Clusters::from_prt(&PortalFile::default())
                .expect("prt1")
                .is_none()
        );
        assert!(matches!(
            Clusters::from_prt(&prt(3, vec![vec![0, 1], vec![1]])),
            Err(VisError::LeafInTwoClusters {
                leaf: 1,
                clusters: [0, 1]
            })
        ));
        assert!(matches!(
            Clusters::from_prt(&prt(3, vec![vec![3]])),
            Err(VisError::ClusterLeaf { leaf: 3, .. })
        ));
    }
}
